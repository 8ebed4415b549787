// Input newer than the headers the layer was built with (issue 15): a flag bit of an extension that Debian 12's
// Vulkan headers (1.3.239) do not name is passed through, never reported, and does not switch off the rules that
// depend on the build's sizes. ALLOW_DATA_ACCESS of VK_KHR_ray_tracing_position_fetch (Vulkan 1.3.253), which
// lavapipe has: its names are spelled out here by value, as an app built on newer headers would pass them.
//
// An extension structure in a pNext chain is passed through too, never reported, and the layer asks the driver
// about that build's sizes with the chain (uncached), so its size rules stay on as well.
//
// Debian 12's Khronos layer predates that extension: it reports the feature structure and the flag bit as unknown,
// and any Khronos layer reports the made-up structure below, so these cases stay out of the runs that stack it
// below asval (tag [newer-input], CMakeLists.txt).
#include <catch2/catch_test_macros.hpp>


#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kPositionFetch = "VK_KHR_ray_tracing_position_fetch";
constexpr VkStructureType kPositionFetchFeatures = static_cast<VkStructureType>(1000481000);
constexpr VkBuildAccelerationStructureFlagsKHR kAllowDataAccess = 0x00000800;

// VkPhysicalDeviceRayTracingPositionFetchFeaturesKHR, as newer headers declare it.
struct PositionFetchFeatures {
  VkStructureType sType = kPositionFetchFeatures;
  void* pNext = nullptr;
  VkBool32 rayTracingPositionFetch = VK_TRUE;
};

TEST_CASE("newer input: a build with ALLOW_DATA_ACCESS (position fetch, newer than the headers) keeps its size rules",
          "[integration][newer-input]") {
  PositionFetchFeatures features;
  vkkit::DeviceOptions options;
  options.extensions = {kPositionFetch};
  options.features = &features;
  {
    // The physical device, before a device that enables the extension is made.
    CheckFixture probe("addresses");
    VkPhysicalDevice gpu = probe.instance().FindRayTracingGpu();
    if (!vkkit::HasDeviceExtension(gpu, kPositionFetch)) SKIP("the device has no " << kPositionFetch);
  }
  CheckFixture f("addresses", options);
  vkkit::Device& device = f.device();
  Scene scene(device);
  VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
  info.flags |= kAllowDataAccess;
  info.pGeometries = &geometry;
  scene.Prepare(info, {1});
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  SECTION("valid twin: built for real, nothing reported") {
    scene.BuildNow({info}, {&range});
    CHECK(f.monitor().Verify() == "");
  }
  SECTION("03671 still fires: buildScratchSize bytes from the scratch address pass the end of its buffer") {
    const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {1});
    vkkit::Buffer exact = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    info.scratchData.deviceAddress = exact.address + 8;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03671");
    IssueOne(device, Command::kDirect, info, &range);
    CHECK(f.monitor().Verify() == "");
    device.Destroy(exact);
  }
}

// A structure no header names, as a newer extension's would be, in a pNext chain.
struct UnknownStructure {
  VkStructureType sType = static_cast<VkStructureType>(1000999000);
  const void* pNext = nullptr;
  uint32_t payload = 0;
};

TEST_CASE("newer input: an extension structure in a geometry's pNext chain is passed through and keeps the build's "
          "size rules",
          "[integration][newer-input]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
  info.pGeometries = &geometry;
  scene.Prepare(info, {1});
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {1});
  vkkit::Buffer exact = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const UnknownStructure unknown;
  geometry.geometry.triangles.pNext = &unknown;  // the layer asks the driver about the sizes with it, uncached
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  // Recorded, never submitted (the structure is made up).
  SECTION("valid twin: the exact scratch, nothing reported") {
    info.scratchData.deviceAddress = exact.address;
  }
  SECTION("03671 still fires: buildScratchSize bytes from the scratch address pass the end of its buffer") {
    info.scratchData.deviceAddress = exact.address + 8;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03671");
  }
  IssueOne(device, Command::kDirect, info, &range);
  CHECK(f.monitor().Verify() == "");
  device.Destroy(exact);
}

}  // namespace
}  // namespace asval_test
