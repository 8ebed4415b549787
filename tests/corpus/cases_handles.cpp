// Family "handles": live source and destination structures of the right level, distinct within one command,
// on buffers bound to memory, and live structures behind a top-level build's instances. Lavapipe has neither
// indirect nor host builds, so those cases also carry 03650 / 03581.
#include <cstring>

#include "corpus.h"
#include "history_helpers.h"
#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::Command;
using asval_test::IssueWithRealRanges;
using asval_test::Ranges;
using asval_test::Scene;

constexpr auto kUpdate = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
constexpr const char* kIndirectFeature =
    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650";
constexpr const char* kHostFeature = "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581";

// A bottom-level build of the scene's one triangle with its own destination and scratch.
struct TriangleBuild {
  explicit TriangleBuild(Scene& scene) : geometry(scene.Triangles()) {
    info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
  }
  TriangleBuild(const TriangleBuild& other) : geometry(other.geometry), info(other.info) {
    info.pGeometries = &geometry;
  }
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

// One call of `infos` (one triangle each) through `command`; host builds get host addresses of the same inputs.
void IssueTriangles(vkkit::Device& device, Scene& scene, Command command,
                    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos) {
  const auto ranges = Ranges(1);
  std::vector<VkAccelerationStructureGeometryKHR> host(infos.size());
  for (size_t i = 0; i < infos.size(); ++i) {
    host[i] = scene.OnHost(infos[i].pGeometries[0]);
    if (command == Command::kHost) infos[i].pGeometries = &host[i];
  }
  IssueWithRealRanges(device, command, infos,
                      std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>(infos.size(), ranges.data()));
}

// The handle of a structure that was live once, destroyed (with its buffer) before the build: a stale handle
// kept in an app's table.
VkAccelerationStructureKHR DestroyedStructure(vkkit::Device& device) {
  vkkit::AccelerationStructure as =
      device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 1 << 16);
  const VkAccelerationStructureKHR handle = as.handle;
  device.Destroy(as);
  return handle;
}

void DestroyedDestination(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild build(scene);
  build.info.dstAccelerationStructure = DestroyedStructure(device);
  IssueTriangles(device, scene, command, {build.info});
}

void DestroyedSource(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild build(scene);
  build.info.mode = kUpdate;
  build.info.srcAccelerationStructure = DestroyedStructure(device);
  IssueTriangles(device, scene, command, {build.info});
}

// A top-level build into a structure created BOTTOM_LEVEL (03699).
void TopIntoBottom(vkkit::Device& device, Command command) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR instances = scene.Instances();
  VkAccelerationStructureBuildGeometryInfoKHR top =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {instances});
  top.pGeometries = &instances;
  scene.Prepare(top, {1}, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  // A host build's instances reference their structures by handle, not by device address.
  VkAccelerationStructureInstanceKHR host_instance{};
  for (int row = 0; row < 3; ++row) host_instance.transform.matrix[row][row] = 1.0f;
  host_instance.mask = 0xff;
  host_instance.accelerationStructureReference = reinterpret_cast<uint64_t>(scene.blas());
  VkAccelerationStructureGeometryKHR host = instances;
  host.geometry.instances.data.hostAddress = &host_instance;
  if (command == Command::kHost) top.pGeometries = &host;
  const auto ranges = Ranges(1);
  IssueWithRealRanges(device, command, {top}, {ranges.data()});
}

// A bottom-level build into a structure created TOP_LEVEL (03700).
void BottomIntoTop(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild build(scene);
  build.info.dstAccelerationStructure = scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, 1 << 16);
  IssueTriangles(device, scene, command, {build.info});
}

// Three builds in one call, the third writing the first one's destination (03698).
void SharedDestination(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild a(scene), b(scene), c(scene);
  c.info.dstAccelerationStructure = a.info.dstAccelerationStructure;
  IssueTriangles(device, scene, command, {a.info, b.info, c.info});
}

// One info updates from the structure another info of the same call rebuilds (03403); the two infos then also read
// and write the same memory (03701).
void SourceIsOtherDestination(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild a(scene), b(scene);
  const auto ranges = Ranges(1);
  scene.BuildNow({a.info}, {ranges.data()});  // built once already, as a refit's source must be
  b.info.mode = kUpdate;
  b.info.srcAccelerationStructure = a.info.dstAccelerationStructure;
  IssueTriangles(device, scene, command, {a.info, b.info});
}

// A structure over a buffer that has no memory (created, never bound, or bound only later).
struct UnboundStructure {
  explicit UnboundStructure(vkkit::Device& d) : device(d) {
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = 1 << 16;
    buffer_info.usage =
        VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    vkkit::Check(vkCreateBuffer(device.handle(), &buffer_info, nullptr, &buffer), "vkCreateBuffer");
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffer;
    info.size = buffer_info.size;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &info, nullptr, &handle),
                 "vkCreateAccelerationStructureKHR");
  }
  // Gives the buffer memory after the structure's creation, which the spec allows.
  void Bind() {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device.handle(), buffer, &req);
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = device.FindMemoryType(req.memoryTypeBits, 0);
    vkkit::Check(vkAllocateMemory(device.handle(), &alloc, nullptr, &memory), "vkAllocateMemory");
    vkkit::Check(vkBindBufferMemory(device.handle(), buffer, memory, 0), "vkBindBufferMemory");
  }
  ~UnboundStructure() {
    device.DestroyAccelerationStructureKHR(device.handle(), handle, nullptr);
    vkDestroyBuffer(device.handle(), buffer, nullptr);
    if (memory) vkFreeMemory(device.handle(), memory, nullptr);
  }
  vkkit::Device& device;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
};

void UnboundDestination(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild build(scene);
  UnboundStructure unbound(device);
  build.info.dstAccelerationStructure = unbound.handle;
  IssueTriangles(device, scene, command, {build.info});
}

void UnboundSource(vkkit::Device& device, Command command) {
  Scene scene(device);
  TriangleBuild build(scene);
  UnboundStructure unbound(device);
  build.info.mode = kUpdate;
  build.info.srcAccelerationStructure = unbound.handle;
  IssueTriangles(device, scene, command, {build.info});
}

}  // namespace

CORPUS_CASE(HandlesDestroyedDst, "handles-destroyed-destination", "handles",
            "a BLAS build into a structure handle destroyed earlier",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03800"}) {
  DestroyedDestination(device, Command::kDirect);
}
CORPUS_CASE(HandlesDestroyedDstIndirect, "handles-destroyed-destination-indirect", "handles",
            "an indirect BLAS build into a structure handle destroyed earlier",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03800", kIndirectFeature}) {
  DestroyedDestination(device, Command::kIndirect);
}
CORPUS_CASE(HandlesDestroyedDstHost, "handles-destroyed-destination-host", "handles",
            "a host BLAS build into a structure handle destroyed earlier",
            {"VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03800", kHostFeature}) {
  DestroyedDestination(device, Command::kHost);
}

CORPUS_CASE(HandlesDestroyedSrc, "handles-destroyed-source", "handles",
            "a BLAS update whose source handle was destroyed earlier",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-srcAccelerationStructure-04629"}) {
  DestroyedSource(device, Command::kDirect);
}
CORPUS_CASE(HandlesDestroyedSrcIndirect, "handles-destroyed-source-indirect", "handles",
            "an indirect BLAS update whose source handle was destroyed earlier",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-srcAccelerationStructure-04629", kIndirectFeature}) {
  DestroyedSource(device, Command::kIndirect);
}
CORPUS_CASE(HandlesDestroyedSrcHost, "handles-destroyed-source-host", "handles",
            "a host BLAS update whose source handle was destroyed earlier",
            {"VUID-vkBuildAccelerationStructuresKHR-srcAccelerationStructure-04629", kHostFeature}) {
  DestroyedSource(device, Command::kHost);
}

CORPUS_CASE(HandlesTopIntoBottom, "handles-tlas-build-into-blas", "handles",
            "a top-level build into a structure created BOTTOM_LEVEL",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03699"}) {
  TopIntoBottom(device, Command::kDirect);
}
CORPUS_CASE(HandlesTopIntoBottomIndirect, "handles-tlas-build-into-blas-indirect", "handles",
            "an indirect top-level build into a structure created BOTTOM_LEVEL",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03699", kIndirectFeature}) {
  TopIntoBottom(device, Command::kIndirect);
}
CORPUS_CASE(HandlesTopIntoBottomHost, "handles-tlas-build-into-blas-host", "handles",
            "a host top-level build into a structure created BOTTOM_LEVEL",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03699", kHostFeature}) {
  TopIntoBottom(device, Command::kHost);
}

CORPUS_CASE(HandlesBottomIntoTop, "handles-blas-build-into-tlas", "handles",
            "a bottom-level build into a structure created TOP_LEVEL",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03700"}) {
  BottomIntoTop(device, Command::kDirect);
}
CORPUS_CASE(HandlesBottomIntoTopIndirect, "handles-blas-build-into-tlas-indirect", "handles",
            "an indirect bottom-level build into a structure created TOP_LEVEL",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03700", kIndirectFeature}) {
  BottomIntoTop(device, Command::kIndirect);
}
CORPUS_CASE(HandlesBottomIntoTopHost, "handles-blas-build-into-tlas-host", "handles",
            "a host bottom-level build into a structure created TOP_LEVEL",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03700", kHostFeature}) {
  BottomIntoTop(device, Command::kHost);
}

CORPUS_CASE(HandlesSharedDst, "handles-two-builds-one-destination", "handles",
            "three BLAS builds in one call, the third into the first one's destination",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
             "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03702"}) {
  SharedDestination(device, Command::kDirect);
}
CORPUS_CASE(HandlesSharedDstIndirect, "handles-two-builds-one-destination-indirect", "handles",
            "three indirect BLAS builds in one call, the third into the first one's destination",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03698",
             "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03702",
             kIndirectFeature}) {
  SharedDestination(device, Command::kIndirect);
}
CORPUS_CASE(HandlesSharedDstHost, "handles-two-builds-one-destination-host", "handles",
            "three host BLAS builds in one call, the third into the first one's destination",
            {"VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
             "VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03702",
             kHostFeature}) {
  SharedDestination(device, Command::kHost);
}

CORPUS_CASE(HandlesSrcIsOtherDst, "handles-update-from-blas-built-in-same-call", "handles",
            "one call that builds a BLAS and, in a second info, updates from that same BLAS",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03403",
             "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03701"}) {
  SourceIsOtherDestination(device, Command::kDirect);
}
CORPUS_CASE(HandlesSrcIsOtherDstIndirect, "handles-update-from-blas-built-in-same-call-indirect", "handles",
            "one indirect call that builds a BLAS and, in a second info, updates from it",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03403",
             "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03701",
             kIndirectFeature}) {
  SourceIsOtherDestination(device, Command::kIndirect);
}
CORPUS_CASE(HandlesSrcIsOtherDstHost, "handles-update-from-blas-built-in-same-call-host", "handles",
            "one host call that builds a BLAS and, in a second info, updates from it",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03403",
             "VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03701",
             kHostFeature}) {
  SourceIsOtherDestination(device, Command::kHost);
}

CORPUS_CASE(HandlesUnboundDst, "handles-destination-buffer-without-memory", "handles",
            "a BLAS build into a structure whose buffer was never bound to memory",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03707"}) {
  UnboundDestination(device, Command::kDirect);
}
CORPUS_CASE(HandlesUnboundDstIndirect, "handles-destination-buffer-without-memory-indirect", "handles",
            "an indirect BLAS build into a structure whose buffer was never bound to memory",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03707", kIndirectFeature}) {
  UnboundDestination(device, Command::kIndirect);
}
CORPUS_CASE(HandlesUnboundSrc, "handles-source-buffer-without-memory", "handles",
            "a BLAS update from a structure whose buffer was never bound to memory",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03708"}) {
  UnboundSource(device, Command::kDirect);
}
CORPUS_CASE(HandlesUnboundSrcIndirect, "handles-source-buffer-without-memory-indirect", "handles",
            "an indirect BLAS update from a structure whose buffer was never bound to memory",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03708", kIndirectFeature}) {
  UnboundSource(device, Command::kIndirect);
}

// The instance's BLAS lost its VkBuffer (the structure handle and the memory stay, so lavapipe reads valid
// bytes); the top-level build is submitted and judged on the instances the device read.
CORPUS_CASE(HandlesInstanceBlasBufferDestroyed, "handles-instance-references-blas-without-buffer", "handles",
            "a TLAS built over two BLASes after the VkBuffer of the second one was destroyed",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03709"}) {
  asval_test::Inputs inputs(device);
  asval_test::Blas a(device, inputs), b(device, inputs);
  asval_test::Tlas tlas(device);
  device.OneShot([&](VkCommandBuffer cb) {
    a.Build(cb, asval_test::Shape{});
    b.Build(cb, asval_test::Shape{});
  });
  vkkit::Buffer instances = tlas.MakeInstances({&a, &b});
  b.DestroyStorageBuffer();
  device.OneShot([&](VkCommandBuffer cb) {
    tlas.Record(cb, instances, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  device.Destroy(instances);
}

// Valid twins: what the handle rules could confuse.

CORPUS_CASE(HandlesGenericStructures, "handles-generic-structures", "handles",
            "a BLAS and a TLAS built into structures created GENERIC", {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR bottom =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
  bottom.pGeometries = &triangles;
  scene.Prepare(bottom, {1}, VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR);
  VkAccelerationStructureGeometryKHR instances = scene.Instances();
  VkAccelerationStructureBuildGeometryInfoKHR top =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {instances});
  top.pGeometries = &instances;
  scene.Prepare(top, {1}, VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR);
  const auto ranges = Ranges(1);
  scene.BuildNow({bottom}, {ranges.data()});
  scene.BuildNow({top}, {ranges.data()});
}

CORPUS_CASE(HandlesManyBuildsThenRefits, "handles-64-builds-then-64-refits", "handles",
            "64 BLAS builds in one call, then 64 in-place refits (src == dst in each info) in one call", {}) {
  Scene scene(device);
  std::vector<TriangleBuild> builds;
  builds.reserve(64);
  for (int k = 0; k < 64; ++k) builds.emplace_back(scene);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  for (TriangleBuild& t : builds) infos.push_back(t.info);
  const auto ranges = Ranges(1);
  const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> range_pointers(64, ranges.data());
  scene.BuildNow(infos, range_pointers);
  for (VkAccelerationStructureBuildGeometryInfoKHR& info : infos) {
    info.mode = kUpdate;
    info.srcAccelerationStructure = info.dstAccelerationStructure;
  }
  scene.BuildNow(infos, range_pointers);
}

CORPUS_CASE(HandlesLateBoundBuffer, "handles-blas-on-buffer-bound-after-creation", "handles",
            "a BLAS created on a buffer before the buffer is bound to memory, then built and refitted", {}) {
  Scene scene(device);
  TriangleBuild build(scene);
  UnboundStructure late(device);
  late.Bind();
  build.info.dstAccelerationStructure = late.handle;
  const auto ranges = Ranges(1);
  scene.BuildNow({build.info}, {ranges.data()});
  build.info.mode = kUpdate;
  build.info.srcAccelerationStructure = late.handle;
  scene.BuildNow({build.info}, {ranges.data()});
}

CORPUS_CASE(HandlesRebuildAfterRecreate, "handles-handle-value-reused-after-recreate", "handles",
            "a BLAS destroyed and a new one created in the same storage, then built and used by a TLAS", {}) {
  asval_test::Inputs inputs(device);
  asval_test::Blas blas(device, inputs);
  asval_test::Tlas tlas(device);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, asval_test::Shape{}); });
  blas.Recreate();
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, asval_test::Shape{}); });
  vkkit::Buffer instances = tlas.MakeInstances({&blas});
  device.OneShot([&](VkCommandBuffer cb) {
    tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  device.Destroy(instances);
}

// srcAccelerationStructure must be a valid handle whenever it is not null, whatever the mode: an app that reuses last
// frame's info for a rebuild keeps a source it has destroyed since.
CORPUS_CASE(HandlesRebuildStaleSource, "handles-rebuild-keeps-destroyed-source", "handles",
            "a BLAS rebuilt (mode BUILD) from an info whose srcAccelerationStructure names a destroyed structure",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-srcAccelerationStructure-04629"}) {
  Scene scene(device);
  TriangleBuild build(scene);
  build.info.srcAccelerationStructure = DestroyedStructure(device);
  IssueTriangles(device, scene, Command::kDirect, {build.info});
}

// 03708 holds an update's source to bound memory; a rebuild does not read its (still valid) source.
CORPUS_CASE(HandlesRebuildUnboundSource, "handles-rebuild-names-source-without-memory", "handles",
            "a BLAS rebuilt (mode BUILD) from an info whose srcAccelerationStructure is live but on a buffer not "
            "bound to memory",
            {}) {
  Scene scene(device);
  TriangleBuild build(scene);
  UnboundStructure unbound(device);
  build.info.srcAccelerationStructure = unbound.handle;
  const auto ranges = Ranges(1);
  scene.BuildNow({build.info}, {ranges.data()});
}

// A loop that assigns destinations by index modulo a table too short: infos 5 and 13 of a batch of 16 write the
// same structure (and therefore the same memory).
CORPUS_CASE(HandlesBatchRepeatedDst, "handles-batch-of-16-one-destination-repeated", "handles",
            "16 BLAS builds in one call, the 14th writing the destination of the 6th",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
             "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03702"}) {
  Scene scene(device);
  std::vector<TriangleBuild> builds;
  builds.reserve(16);
  for (int k = 0; k < 16; ++k) builds.emplace_back(scene);
  builds[13].info.dstAccelerationStructure = builds[5].info.dstAccelerationStructure;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  for (const TriangleBuild& t : builds) infos.push_back(t.info);
  IssueTriangles(device, scene, Command::kDirect, infos);
}

// The rules on one structure named twice hold within one command: the same structure built by two calls of one
// command buffer (a barrier between), and an update in a later call from what an earlier call built, are valid.
CORPUS_CASE(HandlesSameStructureTwoCalls, "handles-one-blas-in-three-calls-of-one-command-buffer", "handles",
            "one command buffer: a BLAS built, built again by a second call, then a third call updating another "
            "structure from it; barriers between the calls",
            {}) {
  Scene scene(device);
  TriangleBuild a(scene), b(scene);
  VkAccelerationStructureBuildGeometryInfoKHR from_a = b.info;
  from_a.mode = kUpdate;
  from_a.srcAccelerationStructure = a.info.dstAccelerationStructure;
  const auto ranges = Ranges(1);
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = ranges.data();
  device.OneShot([&](VkCommandBuffer cb) {
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &a.info, &range_pointer);
    asval_test::BuildBarrier(cb);
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &a.info, &range_pointer);
    asval_test::BuildBarrier(cb);
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &from_a, &range_pointer);
  });
}

// Instances referencing structures by address, some inactive (reference 0), as a scene with hidden objects keeps
// them: the references that 03709 follows are the live ones only.
CORPUS_CASE(HandlesTlasInactiveInstances, "handles-tlas-with-inactive-instances", "handles",
            "a TLAS built over 4 instances, two referencing live BLASes and two inactive (reference 0)", {}) {
  asval_test::Inputs inputs(device);
  asval_test::Blas a(device, inputs), b(device, inputs);
  asval_test::Tlas tlas(device);
  device.OneShot([&](VkCommandBuffer cb) {
    a.Build(cb, asval_test::Shape{});
    b.Build(cb, asval_test::Shape{});
  });
  vkkit::Buffer instances = device.CreateBuffer(4 * sizeof(VkAccelerationStructureInstanceKHR),
                                                VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  const VkDeviceAddress references[4] = {a.address(), 0, b.address(), 0};
  for (int k = 0; k < 4; ++k) {
    VkAccelerationStructureInstanceKHR instance{};
    for (int row = 0; row < 3; ++row) instance.transform.matrix[row][row] = 1.0f;
    instance.transform.matrix[0][3] = 4.0f * static_cast<float>(k);
    instance.mask = 0xff;
    instance.accelerationStructureReference = references[k];
    std::memcpy(static_cast<char*>(instances.mapped) + k * sizeof instance, &instance, sizeof instance);
  }
  device.OneShot([&](VkCommandBuffer cb) {
    tlas.Record(cb, instances, 4, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  device.Destroy(instances);
}

// Two structures sub-allocated in one VkBuffer (as memory allocators place them), built by one call: distinct
// structures at distinct bytes, however close.
CORPUS_CASE(HandlesTwoBlasOneBuffer, "handles-two-blas-in-one-buffer-one-call", "handles",
            "two BLASes created in one storage buffer (offsets 0 and 32768) built by one call", {}) {
  Scene scene(device);
  TriangleBuild first(scene), second(scene);
  asval_test::SharedMemory memory(device, 1 << 16);
  vkkit::Buffer storage = memory.Bind(0, 1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  const VkDeviceSize size = asval_test::DriverSizes(device, first.info, {1}).accelerationStructureSize;
  first.info.dstAccelerationStructure =
      memory.Structure(storage, 0, size, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  second.info.dstAccelerationStructure =
      memory.Structure(storage, 1 << 15, size, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  const auto ranges = Ranges(1);
  scene.BuildNow({first.info, second.info}, {ranges.data(), ranges.data()});
}
