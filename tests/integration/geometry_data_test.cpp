// Family "structure", the geometry data: VkAccelerationStructureGeometryTrianglesDataKHR (vertexStride,
// vertexFormat, indexType) and VkAccelerationStructureGeometryAabbsDataKHR (stride). Structure VUIDs: all three
// commands report the same one.
#include <catch2/catch_test_macros.hpp>

#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kStrideMultiple = "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03735";
constexpr const char* kStrideMax = "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03819";
constexpr const char* kVertexFormat = "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexFormat-03797";
constexpr const char* kIndexType = "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-indexType-03798";
constexpr const char* kAabbStride = "VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545";
constexpr const char* kAabbStrideMax = "VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03820";

// A bottom-level info over one geometry, with a destination sized for the unbroken geometry.
struct OneGeometry {
  OneGeometry(Scene& scene, const VkAccelerationStructureGeometryKHR& g, uint32_t count = 1) : geometry(g) {
    info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
    info.geometryCount = 1;
    info.pGeometries = &geometry;
    scene.Prepare(info, {count});
  }
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

void ExpectEachCommand(CheckFixture& f, const char* vuid, const OneGeometry& build) {
  const auto ranges = Ranges(1);
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(vuid);
    IssueOne(f.device(), command, build.info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

// A vertex format this device cannot build from, if it has one among common colour formats.
VkFormat UnsupportedVertexFormat(CheckFixture& f) {
  VkPhysicalDevice gpu = f.instance().FindRayTracingGpu();
  for (VkFormat format : {VK_FORMAT_R32_SFLOAT, VK_FORMAT_R8_UNORM, VK_FORMAT_R32G32B32_UINT, VK_FORMAT_R64G64B64_SFLOAT}) {
    VkFormatProperties props{};
    vkGetPhysicalDeviceFormatProperties(gpu, format, &props);
    if (!(props.bufferFeatures & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR)) return format;
  }
  return VK_FORMAT_UNDEFINED;
}

TEST_CASE("vertexStride-03735 and 03819: a vertex stride off the component size, or over 2^32-1, is reported",
          "[integration][structure][03735][03819]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  OneGeometry build(scene, scene.Triangles());
  build.geometry.geometry.triangles.vertexStride = 14;  // R32G32B32_SFLOAT: 4-byte components
  ExpectEachCommand(f, kStrideMultiple, build);
  build.geometry.geometry.triangles.vertexStride = VkDeviceSize{1} << 32;  // a multiple of 4, but too large
  ExpectEachCommand(f, kStrideMax, build);
}

TEST_CASE("vertexFormat-03797: a vertex format without the acceleration-structure vertex feature is reported",
          "[integration][structure][03797]") {
  CheckFixture f("structure");
  const VkFormat unsupported = UnsupportedVertexFormat(f);
  REQUIRE(unsupported != VK_FORMAT_UNDEFINED);
  Scene scene(f.device());
  OneGeometry build(scene, scene.Triangles());
  build.geometry.geometry.triangles.vertexFormat = unsupported;
  ExpectEachCommand(f, kVertexFormat, build);
}

TEST_CASE("indexType-03798: an index type other than UINT16, UINT32 or NONE is reported",
          "[integration][structure][03798]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  OneGeometry build(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT32));
  build.geometry.geometry.triangles.indexType = VK_INDEX_TYPE_UINT8_EXT;
  ExpectEachCommand(f, kIndexType, build);
}

TEST_CASE("triangle data valid twin: strides 12 and 44, several vertex formats, every index type the rule allows",
          "[integration][structure][03735][03819][03797][03798]") {
  CheckFixture f;
  Scene scene(f.device());
  const auto ranges = Ranges(1);
  VkAccelerationStructureGeometryKHR wide = scene.Triangles();
  wide.geometry.triangles.vertexData.deviceAddress = scene.Address(Scene::kWideVertices);
  wide.geometry.triangles.vertexStride = 44;  // an interleaved vertex struct
  VkAccelerationStructureGeometryKHR half = scene.Triangles();
  half.geometry.triangles.vertexFormat = VK_FORMAT_R16G16B16A16_SFLOAT;  // reads 8 bytes of each 12-byte record
  for (const VkAccelerationStructureGeometryKHR& g :
       {scene.Triangles(), wide, half, scene.IndexedTriangles(VK_INDEX_TYPE_UINT16),
        scene.IndexedTriangles(VK_INDEX_TYPE_UINT32)}) {
    OneGeometry build(scene, g);
    scene.BuildNow({build.info}, {ranges.data()});
    INFO("format " << g.geometry.triangles.vertexFormat << " stride " << g.geometry.triangles.vertexStride
                   << " index type " << g.geometry.triangles.indexType);
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("stride-03545 and 03820: an AABB stride off 8, or over 2^32-1, is reported",
          "[integration][structure][03545][03820]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  OneGeometry build(scene, scene.Aabbs());
  build.geometry.geometry.aabbs.stride = 28;
  ExpectEachCommand(f, kAabbStride, build);
  build.geometry.geometry.aabbs.stride = (VkDeviceSize{1} << 32) + 8;
  ExpectEachCommand(f, kAabbStrideMax, build);
}

TEST_CASE("stride-03545 and 03820 valid twin: AABB strides of 24 and 48 stay silent",
          "[integration][structure][03545][03820]") {
  CheckFixture f;
  Scene scene(f.device());
  const auto one = Ranges(1);
  const auto two = Ranges(1, 2);
  OneGeometry packed(scene, scene.Aabbs(), 2);  // 24: six floats, the app's own struct
  scene.BuildNow({packed.info}, {two.data()});
  VkAccelerationStructureGeometryKHR sparse = scene.Aabbs();
  sparse.geometry.aabbs.stride = 48;  // every other box
  OneGeometry skipping(scene, sparse);
  scene.BuildNow({skipping.info}, {one.data()});
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
