// Family "alignment", the geometry inputs and the indirect arrays of device builds: vertex data to the
// format's component size, indices to their size, transforms and instances to 16, AABBs and instance pointers
// to 8, indirect addresses and strides to 4. Host builds read host pointers: no alignment rule.
#include <catch2/catch_test_macros.hpp>

#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr PerCommand kVertexAddress = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03711",
                                       "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03711", nullptr};
constexpr PerCommand kIndexAddress = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03712",
                                      "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03712", nullptr};
constexpr PerCommand kTransformAddress = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03810",
                                          "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03810", nullptr};
constexpr PerCommand kAabbAddress = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03714",
                                     "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03714", nullptr};
constexpr PerCommand kInstanceAddress = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03715",
                                         "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03715", nullptr};
constexpr PerCommand kPointerAddress = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03716",
                                        "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03716", nullptr};
constexpr PerCommand kScratchAddress = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710",
                                        "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03710", nullptr};
constexpr const char* kIndirectAddress = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03648";
constexpr const char* kIndirectStride = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectStrides-03787";

constexpr Command kDeviceCommands[] = {Command::kDirect, Command::kIndirect};

struct OneGeometry {
  OneGeometry(Scene& scene, const VkAccelerationStructureGeometryKHR& g,
              VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR)
      : geometry(g) {
    info = Scene::Info(type, {});
    info.geometryCount = 1;
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
  }
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

void ExpectDeviceCommands(CheckFixture& f, const PerCommand& vuid, const OneGeometry& build) {
  const auto ranges = Ranges(1);
  for (Command command : kDeviceCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(vuid.For(command));
    IssueOne(f.device(), command, build.info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("pInfos-03711, 03712 and 03810: misaligned vertex, index and transform addresses are reported",
          "[integration][alignment][03711][03712][03810]") {
  CheckFixture f("alignment");
  Scene scene(f.device());
  OneGeometry vertices(scene, scene.Triangles());
  vertices.geometry.geometry.triangles.vertexData.deviceAddress += 2;  // R32G32B32_SFLOAT: 4-byte components
  ExpectDeviceCommands(f, kVertexAddress, vertices);
  OneGeometry indices(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT32));
  indices.geometry.geometry.triangles.indexData.deviceAddress = scene.Address(Scene::kIndices16);  // 2-aligned only
  ExpectDeviceCommands(f, kIndexAddress, indices);
  OneGeometry transform(scene, scene.Triangles());
  transform.geometry.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms + 8);
  ExpectDeviceCommands(f, kTransformAddress, transform);
}

TEST_CASE("pInfos-03714, 03715 and 03716: misaligned AABB, instance and instance-pointer addresses are reported",
          "[integration][alignment][03714][03715][03716]") {
  CheckFixture f("alignment");
  Scene scene(f.device());
  OneGeometry boxes(scene, scene.Aabbs());
  boxes.geometry.geometry.aabbs.data.deviceAddress += 4;
  ExpectDeviceCommands(f, kAabbAddress, boxes);
  OneGeometry instances(scene, scene.Instances(), VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
  instances.geometry.geometry.instances.data.deviceAddress += 8;
  ExpectDeviceCommands(f, kInstanceAddress, instances);
  OneGeometry pointers(scene, scene.Instances(true), VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
  pointers.geometry.geometry.instances.data.deviceAddress += 4;
  ExpectDeviceCommands(f, kPointerAddress, pointers);
}

TEST_CASE("geometry address alignment valid twin: every input at the alignment it needs, no more, stays silent",
          "[integration][alignment][03711][03712][03810][03714][03715][03716]") {
  CheckFixture f;
  Scene scene(f.device());
  const auto ranges = Ranges(1);
  VkAccelerationStructureGeometryKHR shifted = scene.Triangles();  // 4-aligned, not 8- or 16-aligned
  shifted.geometry.triangles.vertexData.deviceAddress = scene.Address(Scene::kVertices + 4);
  VkAccelerationStructureGeometryKHR transformed = scene.Triangles();
  transformed.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms + 48);
  VkAccelerationStructureGeometryKHR second_box = scene.Aabbs();  // 8-aligned, not 16-aligned
  second_box.geometry.aabbs.data.deviceAddress = scene.Address(Scene::kAabbs + 24);
  VkAccelerationStructureGeometryKHR second_instance = scene.Instances();
  second_instance.geometry.instances.data.deviceAddress = scene.Address(Scene::kInstances + 64);
  VkAccelerationStructureGeometryKHR second_pointer = scene.Instances(true);  // 8-aligned, not 16-aligned
  second_pointer.geometry.instances.data.deviceAddress = scene.Address(Scene::kPointers + 8);
  for (const VkAccelerationStructureGeometryKHR& g :
       {shifted, scene.IndexedTriangles(VK_INDEX_TYPE_UINT16), scene.IndexedTriangles(VK_INDEX_TYPE_UINT32),
        transformed, second_box}) {
    OneGeometry build(scene, g);
    scene.BuildNow({build.info}, {ranges.data()});
  }
  for (const VkAccelerationStructureGeometryKHR& g : {second_instance, second_pointer}) {
    OneGeometry build(scene, g, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
    scene.BuildNow({build.info}, {ranges.data()});
  }
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("pInfos-03710 of the indirect command: a misaligned scratch address is reported",
          "[integration][alignment][03710]") {
  CheckFixture f("alignment");
  Scene scene(f.device());
  OneGeometry build(scene, scene.Triangles());
  build.info.scratchData.deviceAddress += f.device().as_properties().minAccelerationStructureScratchOffsetAlignment / 2;
  const auto ranges = Ranges(1);
  f.monitor().Expect(kScratchAddress.indirect);
  IssueOne(f.device(), Command::kIndirect, build.info, ranges.data());
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("pIndirectDeviceAddresses-03648 and pIndirectStrides-03787: indirect addresses and strides off 4 are "
          "reported",
          "[integration][alignment][03648][03787]") {
  CheckFixture f("alignment");
  Scene scene(f.device());
  OneGeometry build(scene, scene.Triangles());
  const auto ranges = Ranges(1);
  f.monitor().Expect(kIndirectAddress);
  Issue(f.device(), Command::kIndirect, {build.info}, {ranges.data()}, IndirectArgs{0x10002, 16});
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect(kIndirectStride);
  Issue(f.device(), Command::kIndirect, {build.info}, {ranges.data()}, IndirectArgs{0x10000, 18});
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
