// Family "features": the feature each build command needs, build modes, updates without a source, protected
// command buffers. Lavapipe has neither accelerationStructureIndirectBuild nor accelerationStructureHostCommands,
// so every indirect or host build on it also breaks 03650 / 03581: those cases carry that label too.
#include <cstring>
#include <vector>

#include "corpus.h"
#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::Command;
using asval_test::IssueWithRealRanges;
using asval_test::Ranges;
using asval_test::Scene;

constexpr auto kUpdate = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;

// A bottom-level build of the scene's one triangle, with a destination and scratch sized by the driver.
struct TriangleBuild {
  explicit TriangleBuild(Scene& scene) : geometry(scene.Triangles()) {
    info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
  }
  // The build through `command`; host builds get host addresses of the same inputs.
  void Issue(vkkit::Device& device, Scene& scene, Command command) {
    VkAccelerationStructureGeometryKHR host = scene.OnHost(geometry);
    VkAccelerationStructureBuildGeometryInfoKHR issued = info;
    if (command == Command::kHost) issued.pGeometries = &host;
    const auto ranges = Ranges(1);
    IssueWithRealRanges(device, command, {issued}, {ranges.data()});
  }
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

// An update whose srcAccelerationStructure was left null, as when an app forgets to set it for a refit.
void UpdateWithoutSource(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild build(scene);
  build.info.mode = kUpdate;
  build.info.srcAccelerationStructure = VK_NULL_HANDLE;
  build.Issue(device, scene, command);
}

// A mode that is neither BUILD nor UPDATE (e.g. an uninitialised or mis-cast enum).
void InvalidMode(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild build(scene);
  build.info.mode = static_cast<VkBuildAccelerationStructureModeKHR>(2);
  build.Issue(device, scene, command);
}

}  // namespace

CORPUS_CASE(FeaturesUpdateWithoutSource, "features-update-without-source", "features",
            "a refit recorded with mode UPDATE but srcAccelerationStructure left VK_NULL_HANDLE",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-04630"}) {
  UpdateWithoutSource(device, Command::kDirect);
}

CORPUS_CASE(FeaturesUpdateWithoutSourceIndirect, "features-update-without-source-indirect", "features",
            "an indirect refit with srcAccelerationStructure left VK_NULL_HANDLE (lavapipe lacks indirect builds)",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-04630",
             "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650"}) {
  UpdateWithoutSource(device, Command::kIndirect);
}

CORPUS_CASE(FeaturesUpdateWithoutSourceHost, "features-update-without-source-host", "features",
            "a host refit with srcAccelerationStructure left VK_NULL_HANDLE (lavapipe lacks host builds)",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-04630",
             "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"}) {
  UpdateWithoutSource(device, Command::kHost);
}

CORPUS_CASE(FeaturesInvalidMode, "features-invalid-mode", "features",
            "a build whose mode is 2, neither BUILD nor UPDATE",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-mode-04628"}) {
  InvalidMode(device, Command::kDirect);
}

CORPUS_CASE(FeaturesInvalidModeIndirect, "features-invalid-mode-indirect", "features",
            "an indirect build whose mode is 2 (lavapipe lacks indirect builds)",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-mode-04628",
             "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650"}) {
  InvalidMode(device, Command::kIndirect);
}

CORPUS_CASE(FeaturesInvalidModeHost, "features-invalid-mode-host", "features",
            "a host build whose mode is 2 (lavapipe lacks host builds)",
            {"VUID-vkBuildAccelerationStructuresKHR-mode-04628",
             "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"}) {
  InvalidMode(device, Command::kHost);
}

CORPUS_CASE(FeaturesIndirectWithoutFeature, "features-indirect-build-without-feature", "features",
            "an otherwise valid indirect BLAS build, ranges in a real indirect buffer, on a device without "
            "accelerationStructureIndirectBuild",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650"}) {
  Scene scene(device);
  TriangleBuild(scene).Issue(device, scene, Command::kIndirect);
}

CORPUS_CASE(FeaturesHostWithoutFeature, "features-host-build-without-feature", "features",
            "an otherwise valid host BLAS build from mapped inputs, on a device without "
            "accelerationStructureHostCommands",
            {"VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"}) {
  Scene scene(device);
  TriangleBuild(scene).Issue(device, scene, Command::kHost);
}

namespace {

// A command buffer of a pool created PROTECTED. Lavapipe has no protectedMemory, so creating the pool is itself
// invalid (VkCommandPoolCreateInfo-flags-02860, a rule outside asval's families); lavapipe creates it all the same
// and the command buffer is only recorded, never submitted. A layer that stops the pool's creation leaves `cb` null:
// the program records nothing then, as an app stopping on that error would.
struct ProtectedCommandBuffer {
  explicit ProtectedCommandBuffer(vkkit::Device& d) : device(d.handle()) {
    VkCommandPoolCreateInfo info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    info.flags = VK_COMMAND_POOL_CREATE_PROTECTED_BIT;
    info.queueFamilyIndex = 0;  // lavapipe's only queue family, the one vkkit::Device uses
    if (vkCreateCommandPool(device, &info, nullptr, &pool) != VK_SUCCESS) return;
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    vkkit::Check(vkAllocateCommandBuffers(device, &alloc, &cb), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  }
  ~ProtectedCommandBuffer() {
    if (!pool) return;
    vkEndCommandBuffer(cb);
    vkDestroyCommandPool(device, pool, nullptr);
  }
  VkDevice device;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cb = VK_NULL_HANDLE;
};

}  // namespace

CORPUS_CASE(FeaturesProtectedCommandBuffer, "features-build-in-protected-command-buffer", "features",
            "a BLAS build recorded into a command buffer of a protected pool",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-commandBuffer-09547"}) {
  Scene scene(device);
  TriangleBuild build(scene);
  const auto ranges = Ranges(1);
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = ranges.data();
  ProtectedCommandBuffer protected_cb(device);
  if (protected_cb.cb) device.CmdBuildAccelerationStructuresKHR(protected_cb.cb, 1, &build.info, &range_pointer);
}

CORPUS_CASE(FeaturesProtectedCommandBufferIndirect, "features-indirect-build-in-protected-command-buffer", "features",
            "an indirect BLAS build recorded into a command buffer of a protected pool (lavapipe lacks indirect "
            "builds)",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-commandBuffer-09547",
             "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650"}) {
  Scene scene(device);
  TriangleBuild build(scene);
  vkkit::Buffer ranges = device.CreateBuffer(16, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  std::memcpy(ranges.mapped, &range, sizeof range);
  auto indirect = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
      vkGetDeviceProcAddr(device.handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"));
  const uint32_t stride = 16;
  const uint32_t max_count = 1;
  const uint32_t* max_counts = &max_count;
  {
    ProtectedCommandBuffer protected_cb(device);
    if (protected_cb.cb) indirect(protected_cb.cb, 1, &build.info, &ranges.address, &stride, &max_counts);
  }
  device.Destroy(ranges);
}

// Valid twins: what the mode and source rules could confuse.

CORPUS_CASE(FeaturesRefitInPlace, "features-refit-in-place", "features",
            "a BLAS built, then refitted in place (src == dst) in a second submission", {}) {
  Scene scene(device);
  TriangleBuild build(scene);
  const auto ranges = Ranges(1);
  scene.BuildNow({build.info}, {ranges.data()});
  build.info.mode = kUpdate;
  build.info.srcAccelerationStructure = build.info.dstAccelerationStructure;
  scene.BuildNow({build.info}, {ranges.data()});
}

CORPUS_CASE(FeaturesRefitIntoOther, "features-refit-into-other-structure", "features",
            "a BLAS built, then updated from it into a second structure of the same size", {}) {
  Scene scene(device);
  TriangleBuild build(scene);
  const auto ranges = Ranges(1);
  scene.BuildNow({build.info}, {ranges.data()});
  VkAccelerationStructureBuildGeometryInfoKHR update = build.info;
  update.mode = kUpdate;
  update.srcAccelerationStructure = build.info.dstAccelerationStructure;
  scene.Prepare(update, {1});  // a new destination and scratch slice; the source stays
  scene.BuildNow({update}, {ranges.data()});
}

CORPUS_CASE(FeaturesBuildAndRefitOneCall, "features-build-one-refit-another-in-one-call", "features",
            "one vkCmdBuildAccelerationStructuresKHR building one BLAS and refitting another built earlier", {}) {
  Scene scene(device);
  TriangleBuild first(scene), second(scene);
  const auto ranges = Ranges(1);
  scene.BuildNow({first.info}, {ranges.data()});
  VkAccelerationStructureBuildGeometryInfoKHR refit = first.info;
  refit.mode = kUpdate;
  refit.srcAccelerationStructure = first.info.dstAccelerationStructure;
  scene.BuildNow({second.info, refit}, {ranges.data(), ranges.data()});
}

// A device created with VK_KHR_acceleration_structure but without enabling its accelerationStructure feature (an
// app that forgot the feature structure in pNext), then an empty build recorded on it.
CORPUS_CASE(FeaturesNoAccelerationStructureFeature, "features-build-without-as-feature",
            "features",
            "a device with the acceleration-structure extension but the accelerationStructure feature not enabled "
            "records a build",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-accelerationStructure-08923",
             // No structure can be created without the feature (vkCreateAccelerationStructureKHR-03611), so the
             // build has no destination either.
             "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03800"}) {
  asval_test::FeaturelessDevice featureless(corpus::CurrentInstance().FindRayTracingGpu());
  // The build names no structure (none can be created) and builds no geometry.
  VkAccelerationStructureBuildGeometryInfoKHR empty{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  empty.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  const VkAccelerationStructureBuildRangeInfoKHR* no_ranges = nullptr;
  featureless.CmdBuild(featureless.cb(), 1, &empty, &no_ranges);
}

// An app that reuses its refit info for a full rebuild and leaves srcAccelerationStructure set (to the structure
// itself, live): only UPDATE reads the source, so the update rules do not apply.
CORPUS_CASE(FeaturesRebuildKeepsSource, "features-rebuild-info-keeps-source", "features",
            "a BLAS built, refitted in place, then rebuilt with mode BUILD from the refit's info (source still set)",
            {}) {
  Scene scene(device);
  TriangleBuild build(scene);
  const auto ranges = Ranges(1);
  scene.BuildNow({build.info}, {ranges.data()});
  build.info.mode = kUpdate;
  build.info.srcAccelerationStructure = build.info.dstAccelerationStructure;
  scene.BuildNow({build.info}, {ranges.data()});
  build.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  scene.BuildNow({build.info}, {ranges.data()});
}

// A per-frame refit of many BLASes in one call where one info's source was never filled in (e.g. a mesh added this
// frame takes the refit path).
CORPUS_CASE(FeaturesBatchRefitOneWithoutSource, "features-batch-refit-one-without-source", "features",
            "8 BLASes built, then refitted in place in one call in which the 4th info has no source",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-04630"}) {
  Scene scene(device);
  std::vector<TriangleBuild> builds;
  builds.reserve(8);
  for (int k = 0; k < 8; ++k) builds.emplace_back(scene);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  for (const TriangleBuild& t : builds) infos.push_back(t.info);
  const auto ranges = Ranges(1);
  const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> range_pointers(8, ranges.data());
  scene.BuildNow(infos, range_pointers);
  for (VkAccelerationStructureBuildGeometryInfoKHR& info : infos) {
    info.mode = kUpdate;
    info.srcAccelerationStructure = info.dstAccelerationStructure;
  }
  infos[3].srcAccelerationStructure = VK_NULL_HANDLE;
  scene.BuildNow(infos, range_pointers);
}

// Pool flags other than PROTECTED leave a command buffer unprotected: a per-frame transient, resettable pool whose
// one command buffer is reset and re-recorded every frame.
CORPUS_CASE(FeaturesTransientResettablePool, "features-builds-in-transient-resettable-pool", "features",
            "a BLAS built, then refitted 3 times, each frame re-recording one command buffer of a TRANSIENT | "
            "RESET_COMMAND_BUFFER pool",
            {}) {
  Scene scene(device);
  TriangleBuild build(scene);
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = 0;  // lavapipe's only queue family, the one vkkit::Device uses
  VkCommandPool pool = VK_NULL_HANDLE;
  vkkit::Check(vkCreateCommandPool(device.handle(), &pool_info, nullptr, &pool), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateCommandBuffers(device.handle(), &alloc, &cb), "vkAllocateCommandBuffers");
  const auto ranges = Ranges(1);
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = ranges.data();
  for (int frame = 0; frame < 4; ++frame) {
    vkkit::Check(vkResetCommandBuffer(cb, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &build.info, &range_pointer);
    vkkit::Check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    vkkit::Check(vkQueueSubmit(device.queue(), 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
    vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
    build.info.mode = kUpdate;  // every later frame refits
    build.info.srcAccelerationStructure = build.info.dstAccelerationStructure;
  }
  vkDestroyCommandPool(device.handle(), pool, nullptr);
}
