// Family "features" for indirect builds on asval's test driver (docs/testing.md): indirect builds that reach a
// driver which executes them. The layers of the run sit above the test driver.
#include <catch2/catch_test_macros.hpp>
#include <cstring>

#include "memory_placement_helpers.h"
#include "on_test_driver.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr const char* k03650 =
    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650";

vkkit::DeviceOptions IndirectBuild() {
  vkkit::DeviceOptions options;
  options.indirect_build = true;
  return options;
}

TEST_CASE(
    "03650 valid twin on the test driver: indirect builds with accelerationStructureIndirectBuild stay "
    "silent and execute",
    "[integration][features][test-driver][valid]") {
  const OnTestDriver driver;
  CheckFixture f("features", IndirectBuild());
  vkkit::Device& device = f.device();
  Scene scene(device);
  for (const auto& geometry : {scene.Triangles(), scene.IndexedTriangles(VK_INDEX_TYPE_UINT16), scene.Aabbs()}) {
    VkAccelerationStructureBuildGeometryInfoKHR info =
        Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
    vkkit::Buffer ranges =
        device.CreateBuffer(sizeof(VkAccelerationStructureBuildRangeInfoKHR), VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
    std::memcpy(ranges.mapped, &range, sizeof(range));
    auto indirect = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
        vkGetDeviceProcAddr(device.handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"));
    const uint32_t stride = sizeof(range);
    const uint32_t max_count = 1;
    const uint32_t* max_counts = &max_count;
    device.OneShot([&](VkCommandBuffer cb) { indirect(cb, 1, &info, &ranges.address, &stride, &max_counts); });
    device.Destroy(ranges);
  }
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("03650 on the test driver: an indirect build on a device that did not enable the feature is reported",
          "[integration][features][test-driver][03650]") {
  const OnTestDriver driver;
  CheckFixture f("features");  // the driver offers indirect builds; this device does not enable them
  vkkit::Device& device = f.device();
  Scene scene(device);
  const VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
  info.pGeometries = &geometry;
  scene.Prepare(info, {1});
  f.monitor().Expect(k03650);
  RecordIndirect(device, {info}, {scene.Address(Scene::kInstances)}, {16}, {{1}});
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
