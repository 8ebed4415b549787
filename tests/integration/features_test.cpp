// Family "features": the feature each build command needs, build modes, protected command buffers.
// Lavapipe has neither accelerationStructureIndirectBuild nor accelerationStructureHostCommands, so every
// indirect or host build through it also reports 03650 / 03581 while this family is on; their valid twins
// (the features enabled) are unit tests (tests/unit/record_checks_unit_test.cpp).
#include <catch2/catch_test_macros.hpp>

#include <cstring>

#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr PerCommand kFeature = {"VUID-vkCmdBuildAccelerationStructuresKHR-accelerationStructure-08923",
                                 "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650",
                                 "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"};
constexpr PerCommand kMode = {"VUID-vkCmdBuildAccelerationStructuresKHR-mode-04628",
                              "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-mode-04628",
                              "VUID-vkBuildAccelerationStructuresKHR-mode-04628"};
constexpr PerCommand kUpdateSource = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-04630",
                                      "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-04630",
                                      "VUID-vkBuildAccelerationStructuresKHR-pInfos-04630"};
constexpr PerCommand kProtected = {"VUID-vkCmdBuildAccelerationStructuresKHR-commandBuffer-09547",
                                   "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-commandBuffer-09547", nullptr};

// Lavapipe lacks the indirect and host features: with this family on, those commands also report them.
void ExpectMissingFeature(Monitor& monitor, Command command) {
  if (command != Command::kDirect) monitor.Expect(kFeature.For(command));
}

TEST_CASE("08923: a build on a device without the accelerationStructure feature is reported",
          "[integration][features][08923]") {
  CheckFixture f("features");
  // The extension without its feature: a valid device, on which no build may be recorded.
  FeaturelessDevice featureless(f.instance().FindRayTracingGpu());
  auto build = featureless.CmdBuild;
  REQUIRE(build);
  VkAccelerationStructureBuildGeometryInfoKHR empty{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  empty.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  const VkAccelerationStructureBuildRangeInfoKHR* no_ranges = nullptr;
  f.monitor().Expect(kFeature.direct);
  build(featureless.cb(), 1, &empty, &no_ranges);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("08923 valid twin: with the feature enabled a build stays silent", "[integration][features][08923]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  vkkit::TriangleBuild build(device);
  device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); });
  CHECK(f.monitor().Verify() == "");
  build.Release(device);
}

TEST_CASE("03650 and 03581: indirect and host builds without their features are reported",
          "[integration][features][03650][03581]") {
  CheckFixture f("features");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});
  const auto ranges = Ranges(1);
  for (Command command : {Command::kIndirect, Command::kHost}) {
    INFO(CommandName(command));
    f.monitor().Expect(kFeature.For(command));
    IssueOne(f.device(), command, info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("mode-04628: a mode that is neither BUILD nor UPDATE is reported by all three commands",
          "[integration][features][04628]") {
  CheckFixture f("features");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});
  info.mode = static_cast<VkBuildAccelerationStructureModeKHR>(2);
  const auto ranges = Ranges(1);
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    ExpectMissingFeature(f.monitor(), command);
    f.monitor().Expect(kMode.For(command));
    IssueOne(f.device(), command, info, ranges.data());
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == (command == Command::kDirect ? 1u : 2u));
    bool named = false;
    for (const Message& m : messages) named |= m.text.find("pInfos[0].mode (2)") != std::string::npos;
    CHECK(named);
  }
}

TEST_CASE("pInfos-04630: an update without a source is reported by all three commands",
          "[integration][features][04630]") {
  CheckFixture f("features");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  const auto ranges = Ranges(1);
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    ExpectMissingFeature(f.monitor(), command);
    f.monitor().Expect(kUpdateSource.For(command));
    IssueOne(f.device(), command, info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("mode-04628 and pInfos-04630 valid twins: a build, an in-place update and an update into another "
          "structure stay silent",
          "[integration][features][04628][04630]") {
  CheckFixture f;
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR build =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
  build.pGeometries = &triangles;
  scene.Prepare(build, {1});
  const auto ranges = Ranges(1);
  scene.BuildNow({build}, {ranges.data()});
  CHECK(f.monitor().Verify() == "");

  VkAccelerationStructureBuildGeometryInfoKHR in_place = build;
  in_place.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  in_place.srcAccelerationStructure = build.dstAccelerationStructure;
  scene.BuildNow({in_place}, {ranges.data()});
  CHECK(f.monitor().Verify() == "");

  VkAccelerationStructureBuildGeometryInfoKHR into_other = in_place;
  scene.Prepare(into_other, {1});  // a new destination and scratch slice; the source stays
  scene.BuildNow({into_other}, {ranges.data()});
  CHECK(f.monitor().Verify() == "");
}

// A protected command pool on a device without protectedMemory is itself invalid (the Khronos layer reports
// VUID-VkCommandPoolCreateInfo-flags-02860), hence [passes-invalid-down]; lavapipe creates it all the same
// and its command buffers are only recorded, never submitted.
struct ProtectedPool {
  explicit ProtectedPool(CheckFixture& f) : device(f.device().handle()) {
    VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    info.flags = VK_COMMAND_POOL_CREATE_PROTECTED_BIT;
    info.queueFamilyIndex = ComputeQueueFamily(f.instance().FindRayTracingGpu());
    vkkit::Check(vkCreateCommandPool(device, &info, nullptr, &pool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    vkkit::Check(vkAllocateCommandBuffers(device, &alloc, &cb), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  }
  ~ProtectedPool() {
    vkEndCommandBuffer(cb);
    vkDestroyCommandPool(device, pool, nullptr);
  }
  VkDevice device;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cb = VK_NULL_HANDLE;
};

TEST_CASE("09547: a build recorded into a protected command buffer is reported",
          "[integration][features][09547][passes-invalid-down]") {
  CheckFixture f("features");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});
  const auto ranges = Ranges(1);
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = ranges.data();
  ProtectedPool pool(f);

  f.monitor().Expect(kProtected.direct);
  f.device().CmdBuildAccelerationStructuresKHR(pool.cb, 1, &info, &range_pointer);
  CHECK(f.monitor().Verify() == "");

  auto indirect = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
      vkGetDeviceProcAddr(f.device().handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"));
  const VkDeviceAddress address = scene.Address(0);
  const uint32_t stride = 16;
  const uint32_t max_count = 1;
  const uint32_t* max_counts = &max_count;
  f.monitor().Expect(kFeature.indirect);
  f.monitor().Expect(kProtected.indirect);
  indirect(pool.cb, 1, &info, &address, &stride, &max_counts);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("09547 valid twin: unprotected command buffers stay silent, also once a protected pool exists",
          "[integration][features][09547][passes-invalid-down]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  vkkit::TriangleBuild build(device);
  device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); });
  CHECK(f.monitor().Verify() == "");
  {
    ProtectedPool pool(f);  // the layer now looks the command buffer up instead of taking its fast path
    device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); });
    CHECK(f.monitor().Verify() == "");
  }
  build.Release(device);
}

}  // namespace
}  // namespace asval_test
