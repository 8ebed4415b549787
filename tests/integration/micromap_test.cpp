// VK_EXT_opacity_micromap in the KHR builds (family "structure"): the
// VkAccelerationStructureTrianglesOpacityMicromapEXT a triangles geometry chains names one array of usage counts
// (pUsageCounts-07335), and an index type (10719) and stride (10722, 10723) the build can read. Through the loader on
// the test driver, which exposes the extension over lavapipe and passes the builds down without it (tests/driver).
#include <catch2/catch_test_macros.hpp>

#include "build_extension_helpers.h"
#include "on_test_driver.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

// One triangle whose opacity comes from `micromap` (its pNext); `micromap` must outlive the build.
struct MicromapTriangle {
  MicromapTriangle(Scene& scene, const VkAccelerationStructureTrianglesOpacityMicromapEXT& m) : micromap(m) {
    geometry = scene.Triangles();
    geometry.geometry.triangles.pNext = &micromap;
    info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
    info.pGeometries = &geometry;
    info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT;
    scene.Prepare(info, {1});
  }
  MicromapTriangle(const MicromapTriangle&) = delete;
  VkAccelerationStructureTrianglesOpacityMicromapEXT micromap;
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

TEST_CASE(
    "micromap: usage counts given twice, an index type the build cannot read, and index strides that are not a "
    "multiple of the index size or beyond 2^32-1 are reported (pUsageCounts-07335, indexType-10719, "
    "indexType-10722, indexType-10723)",
    "[integration][structure][micromap][test-driver][newer-input]") {
  const OnTestDriver driver;
  const OpacityMicromapDevice micromap_device;
  CheckFixture f("structure", micromap_device.options);
  vkkit::Device& device = f.device();
  Scene scene(device);
  vkkit::Buffer special = SpecialIndexBuffer(device);
  const Micromap micromap(device);
  const VkMicromapUsageEXT usage{0, 1, VK_OPACITY_MICROMAP_FORMAT_2_STATE_EXT};
  const VkMicromapUsageEXT* usage_pointer = &usage;
  VkAccelerationStructureTrianglesOpacityMicromapEXT twice = OpacityFromSpecialIndices(special, micromap);
  twice.usageCountsCount = 1;
  twice.pUsageCounts = &usage;
  twice.ppUsageCounts = &usage_pointer;
  VkAccelerationStructureTrianglesOpacityMicromapEXT uint8 = OpacityFromSpecialIndices(special, micromap);
  uint8.indexType = VK_INDEX_TYPE_UINT8_EXT;
  VkAccelerationStructureTrianglesOpacityMicromapEXT odd = OpacityFromSpecialIndices(special, micromap);
  odd.indexStride = 6;
  VkAccelerationStructureTrianglesOpacityMicromapEXT huge = OpacityFromSpecialIndices(special, micromap);
  huge.indexStride = VkDeviceSize{1} << 32;
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-pUsageCounts-07335");
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-indexType-10719");
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-indexType-10722");
  f.monitor().Expect("VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-indexType-10723");
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  for (const VkAccelerationStructureTrianglesOpacityMicromapEXT* m : {&twice, &uint8, &odd, &huge}) {
    const MicromapTriangle build(scene, *m);
    device.OneShot([&](VkCommandBuffer cb) { device.CmdBuildAccelerationStructuresKHR(cb, 1, &build.info, &ranges); });
  }
  CHECK(f.monitor().Verify() == "");
  device.Destroy(special);
}

TEST_CASE(
    "micromap valid twin: 32-bit special indices 4 or 8 bytes apart, with usage counts in one array or none, "
    "stay silent and execute",
    "[integration][structure][micromap][test-driver][valid][newer-input]") {
  const OnTestDriver driver;
  const OpacityMicromapDevice micromap_device;
  CheckFixture f(nullptr, micromap_device.options);
  vkkit::Device& device = f.device();
  Scene scene(device);
  vkkit::Buffer special = SpecialIndexBuffer(device);
  const Micromap micromap(device);
  const VkMicromapUsageEXT usage{0, 1, VK_OPACITY_MICROMAP_FORMAT_2_STATE_EXT};
  VkAccelerationStructureTrianglesOpacityMicromapEXT none = OpacityFromSpecialIndices(special, micromap);
  VkAccelerationStructureTrianglesOpacityMicromapEXT counted = OpacityFromSpecialIndices(special, micromap);
  counted.indexStride = 8;
  counted.usageCountsCount = 1;
  counted.pUsageCounts = &usage;
  const MicromapTriangle a(scene, none), b(scene, counted);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({a.info, b.info}, {&range, &range});
  CHECK(f.monitor().Verify() == "");
  device.Destroy(special);
}

}  // namespace
}  // namespace asval_test
