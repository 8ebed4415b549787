// Family "aliasing": memory one build of a command writes (destination, scratch) is not read or written by another
// build of the same command, compared over the bytes the driver says each build touches, in VkDeviceMemory offsets.
// Direct builds are recorded, submitted and waited for (two builds writing the same bytes is a fault of the
// execution); indirect and host builds only go through calls a layer skips (lavapipe has neither). The valid twins
// are what sub-allocating programs do: thousands of infos on slices of one scratch buffer, structures side by side
// in one VkDeviceMemory, in-place refits.
#include <cstring>
#include <vector>

#include "corpus.h"
#include "history_helpers.h"
#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::CallHostBuild;
using asval_test::Command;
using asval_test::Commands;
using asval_test::DriverSizes;
using asval_test::IssueWithRealRanges;
using asval_test::RoundUp;
using asval_test::Scene;
using asval_test::SharedMemory;

constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
constexpr VkBufferUsageFlags kAsStorage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
// Lavapipe has no accelerationStructureHostCommands: every host build also breaks the feature rule.
// Lavapipe has no accelerationStructureIndirectBuild: every indirect build also breaks that feature rule.
constexpr const char* kIndirectFeature =
    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650";
constexpr const char* kHostFeature = "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581";

// n one-triangle BLAS infos over the scene's vertices, each with its own destination and scratch slice. For host
// builds, Host() gives the same infos with host pointers (inputs in the scene's mapping, scratch 32 KiB apart).
struct TriangleInfos {
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureGeometryKHR host_geometry;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges;
  std::vector<unsigned char> host_scratch;
  TriangleInfos(Scene& scene, size_t n) : geometry(scene.Triangles()), host_geometry(scene.OnHost(geometry)) {
    for (size_t i = 0; i < n; ++i) {
      infos.push_back(Scene::Info(kBottom, {geometry}));
      infos.back().pGeometries = &geometry;
      scene.Prepare(infos.back(), {1});
      ranges.push_back(&range);
    }
    host_scratch.resize(32768 * (n + 1));
  }
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> Host(std::vector<VkAccelerationStructureBuildGeometryInfoKHR> in) {
    for (size_t i = 0; i < in.size(); ++i) {
      in[i].pGeometries = &host_geometry;
      in[i].scratchData.hostAddress = host_scratch.data() + 32768 * i;
    }
    return in;
  }
};

// One vkCmdBuildAccelerationStructuresKHR of `infos`, submitted and waited for.
void SubmitBuilds(vkkit::Device& device, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                  const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges) {
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  device.CmdBuildAccelerationStructuresKHR(cb, static_cast<uint32_t>(infos.size()), infos.data(), ranges.data());
  commands.End(cb);
  commands.Submit(cb);
}

// Two structures created at the same offset of one buffer (distinct handles, the same bytes).
struct SameBytes {
  Scene scene;
  TriangleInfos builds;
  VkDeviceSize size;
  SharedMemory memory;
  vkkit::Buffer storage;
  explicit SameBytes(vkkit::Device& device)
      : scene(device), builds(scene, 2), size(DriverSizes(device, builds.infos[0], {1}).accelerationStructureSize),
        memory(device, 1 << 16), storage(memory.Bind(0, 8192, kAsStorage | kStorage)) {
    builds.infos[0].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom);
    builds.infos[1].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom);
  }
};

// infos[0] refits `source` (built for real first, at offset 0 of a shared buffer) into its own destination;
// infos[1] is a build of another structure.
struct UpdateOverShared {
  Scene scene;
  TriangleInfos builds;
  VkDeviceSize size;
  SharedMemory memory;
  vkkit::Buffer storage;
  VkAccelerationStructureKHR source;
  explicit UpdateOverShared(vkkit::Device& device)
      : scene(device), builds(scene, 2), size(DriverSizes(device, builds.infos[0], {1}).accelerationStructureSize),
        memory(device, 1 << 16), storage(memory.Bind(0, 8192, kAsStorage | kStorage)),
        source(memory.Structure(storage, 0, size, kBottom)) {
    VkAccelerationStructureBuildGeometryInfoKHR first = builds.infos[0];
    first.dstAccelerationStructure = source;
    scene.BuildNow({first}, {&builds.range});
    builds.infos[0].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    builds.infos[0].srcAccelerationStructure = source;
  }
  // 03701: infos[1]'s destination is another structure over the source's bytes.
  void DestinationOverSource() { builds.infos[1].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom); }
  // 03668: the update writes another structure over its own source's bytes.
  void UpdateIntoTwin() { builds.infos[0].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom); }
};

// ---- scratch shared by two infos (03704)

CORPUS_CASE(ScratchSharedDirect, "aliasing-scratch-shared-by-two-builds", "aliasing",
            "3 BLAS builds in one call, the second and third given the same scratch address (a batching bug)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-scratchData-03704"}) {
  Scene scene(device);
  TriangleInfos builds(scene, 3);
  builds.infos[2].scratchData = builds.infos[1].scratchData;
  SubmitBuilds(device, builds.infos, builds.ranges);
}

CORPUS_CASE(ScratchOverlapInMemory, "aliasing-scratch-overlap-through-two-buffers", "aliasing",
            "2 BLAS builds in one call whose scratch lies in two different buffers bound 64 bytes apart in one "
            "VkDeviceMemory, so their scratch bytes overlap",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-scratchData-03704"}) {
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer a = memory.Bind(0, 4096, kStorage);
  vkkit::Buffer b = memory.Bind(64, 4096, kStorage);
  builds.infos[0].scratchData.deviceAddress = a.address + 32;
  builds.infos[1].scratchData.deviceAddress = b.address;
  SubmitBuilds(device, builds.infos, builds.ranges);
}

CORPUS_CASE(ScratchSharedIndirect, "aliasing-indirect-scratch-shared-by-two-builds", "aliasing",
            "2 indirect BLAS builds in one call given the same scratch address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-scratchData-03704", kIndirectFeature}) {
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  builds.infos[1].scratchData = builds.infos[0].scratchData;
  IssueWithRealRanges(device, Command::kIndirect, builds.infos, builds.ranges);
}

CORPUS_CASE(ScratchSharedHost, "aliasing-host-scratch-shared-by-two-builds", "aliasing",
            "2 host BLAS builds in one call given the same host scratch pointer",
            {"VUID-vkBuildAccelerationStructuresKHR-scratchData-03704", kHostFeature}) {
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos = builds.Host(builds.infos);
  infos[1].scratchData = infos[0].scratchData;
  CallHostBuild(device, infos, builds.ranges);
}

// ---- two destinations over the same bytes (03702)

CORPUS_CASE(DestinationsSameBytesDirect, "aliasing-two-destinations-same-memory", "aliasing",
            "2 BLAS builds in one call into two structures created at the same offset of one buffer",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03702"}) {
  SameBytes s(device);
  SubmitBuilds(device, s.builds.infos, s.builds.ranges);
}

CORPUS_CASE(DestinationsSameBytesIndirect, "aliasing-indirect-two-destinations-same-memory", "aliasing",
            "2 indirect BLAS builds in one call into two structures at the same offset of one buffer",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03702", kIndirectFeature}) {
  SameBytes s(device);
  IssueWithRealRanges(device, Command::kIndirect, s.builds.infos, s.builds.ranges);
}

CORPUS_CASE(DestinationsSameBytesHost, "aliasing-host-two-destinations-same-memory", "aliasing",
            "2 host BLAS builds in one call into two structures at the same offset of one buffer",
            {"VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03702", kHostFeature}) {
  SameBytes s(device);
  CallHostBuild(device, s.builds.Host(s.builds.infos), s.builds.ranges);
}

// ---- a destination over its own scratch (03703)

CORPUS_CASE(DestinationOverScratchDirect, "aliasing-destination-over-own-scratch", "aliasing",
            "a BLAS build whose scratch address is the start of its own destination's bytes (one buffer used for "
            "both)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03703"}) {
  Scene scene(device);
  TriangleInfos builds(scene, 1);
  const VkDeviceSize size = DriverSizes(device, builds.infos[0], {1}).accelerationStructureSize;
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer storage = memory.Bind(0, 8192, kAsStorage | kStorage);
  builds.infos[0].dstAccelerationStructure = memory.Structure(storage, 1024, size, kBottom);
  builds.infos[0].scratchData.deviceAddress = storage.address + 1024;
  SubmitBuilds(device, builds.infos, builds.ranges);
}

CORPUS_CASE(DestinationOverScratchIndirect, "aliasing-indirect-destination-over-own-scratch", "aliasing",
            "an indirect BLAS build whose scratch address is the start of its own destination's bytes",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03703", kIndirectFeature}) {
  Scene scene(device);
  TriangleInfos builds(scene, 1);
  const VkDeviceSize size = DriverSizes(device, builds.infos[0], {1}).accelerationStructureSize;
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer storage = memory.Bind(0, 8192, kAsStorage | kStorage);
  builds.infos[0].dstAccelerationStructure = memory.Structure(storage, 1024, size, kBottom);
  builds.infos[0].scratchData.deviceAddress = storage.address + 1024;
  IssueWithRealRanges(device, Command::kIndirect, builds.infos, builds.ranges);
}

// ---- another info's scratch over an update's source (03705)

CORPUS_CASE(ScratchOverSourceDirect, "aliasing-scratch-over-refit-source", "aliasing",
            "a refit and a build in one call, the build's scratch inside the bytes of the refit's source",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-scratchData-03705"}) {
  UpdateOverShared u(device);
  u.builds.infos[1].scratchData.deviceAddress = u.storage.address + 64;
  SubmitBuilds(device, u.builds.infos, u.builds.ranges);
}

CORPUS_CASE(ScratchOverSourceIndirect, "aliasing-indirect-scratch-over-refit-source", "aliasing",
            "an indirect refit and build in one call, the build's scratch inside the bytes of the refit's source",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-scratchData-03705", kIndirectFeature}) {
  UpdateOverShared u(device);
  u.builds.infos[1].scratchData.deviceAddress = u.storage.address + 64;
  IssueWithRealRanges(device, Command::kIndirect, u.builds.infos, u.builds.ranges);
}

// ---- destinations over an update's source (03701, 03668)

CORPUS_CASE(DestinationOverSourceDirect, "aliasing-destination-over-refit-source", "aliasing",
            "a refit and a build in one call, the build's destination another structure over the refit's source",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03701"}) {
  UpdateOverShared u(device);
  u.DestinationOverSource();
  SubmitBuilds(device, u.builds.infos, u.builds.ranges);
}

CORPUS_CASE(DestinationOverSourceIndirect, "aliasing-indirect-destination-over-refit-source", "aliasing",
            "an indirect refit and build in one call, the build's destination over the refit's source",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03701", kIndirectFeature}) {
  UpdateOverShared u(device);
  u.DestinationOverSource();
  IssueWithRealRanges(device, Command::kIndirect, u.builds.infos, u.builds.ranges);
}

CORPUS_CASE(DestinationOverSourceHost, "aliasing-host-destination-over-refit-source", "aliasing",
            "a host refit and build in one call, the build's destination over the refit's source",
            {"VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03701", kHostFeature}) {
  UpdateOverShared u(device);
  u.DestinationOverSource();
  CallHostBuild(device, u.builds.Host(u.builds.infos), u.builds.ranges);
}

CORPUS_CASE(RefitIntoTwinDirect, "aliasing-refit-into-structure-over-source", "aliasing",
            "a refit from one structure into another structure created over the same bytes (neither in place nor "
            "apart)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03668"}) {
  UpdateOverShared u(device);
  u.UpdateIntoTwin();
  SubmitBuilds(device, u.builds.infos, u.builds.ranges);
}

CORPUS_CASE(RefitIntoTwinIndirect, "aliasing-indirect-refit-into-structure-over-source", "aliasing",
            "an indirect refit into another structure created over its source's bytes",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03668", kIndirectFeature}) {
  UpdateOverShared u(device);
  u.UpdateIntoTwin();
  IssueWithRealRanges(device, Command::kIndirect, u.builds.infos, u.builds.ranges);
}

CORPUS_CASE(RefitIntoTwinHost, "aliasing-host-refit-into-structure-over-source", "aliasing",
            "a host refit into another structure created over its source's bytes",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03668", kHostFeature}) {
  UpdateOverShared u(device);
  u.UpdateIntoTwin();
  CallHostBuild(device, u.builds.Host(u.builds.infos), u.builds.ranges);
}

// ---- TLAS instances referencing what the same command writes (None-03407, 03706)

// BLASes a and b built for real, `overlap` created 256 bytes into b's storage, a TLAS over up to 4 instances.
struct TogetherRig {
  vkkit::Device& device;
  asval_test::Inputs inputs;
  asval_test::Blas a, b, overlap;
  asval_test::Tlas tlas;
  explicit TogetherRig(vkkit::Device& d)
      : device(d), inputs(d), a(d, inputs), b(d, inputs), overlap(d, inputs, &b, 256), tlas(d) {
    d.OneShot([&](VkCommandBuffer cb) {
      a.Build(cb, asval_test::Shape{});
      b.Build(cb, asval_test::Shape{});
    });
  }
  // ONE vkCmdBuildAccelerationStructuresKHR of `blases` (built again) then the TLAS over instances of `referenced`,
  // submitted and waited for.
  void BuildTogether(const std::vector<const asval_test::Blas*>& blases,
                     const std::vector<const asval_test::Blas*>& referenced) {
    vkkit::Buffer instances = tlas.MakeInstances(referenced);
    std::vector<asval_test::BuildInfo> infos;
    for (const asval_test::Blas* blas : blases) infos.push_back(blas->Info(asval_test::Shape{}));
    infos.push_back(tlas.Info(instances, static_cast<uint32_t>(referenced.size()),
                              VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR));
    std::vector<const asval_test::BuildInfo*> pointers;
    for (const asval_test::BuildInfo& info : infos) pointers.push_back(&info);
    Commands commands(device);
    VkCommandBuffer cb = commands.Begin();
    asval_test::RecordBuilds(device, cb, pointers);
    commands.End(cb);
    commands.Submit(cb);
    device.Destroy(instances);
  }
};

CORPUS_CASE(InstanceOfDestinationDirect, "aliasing-tlas-instance-of-blas-built-in-same-call", "aliasing",
            "a BLAS rebuilt and a TLAS referencing it in the same vkCmdBuildAccelerationStructuresKHR (the TLAS "
            "build may run before the BLAS build ends)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-None-03407",
             "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03706"}) {
  TogetherRig rig(device);
  rig.BuildTogether({&rig.a}, {&rig.b, &rig.a});
}

CORPUS_CASE(InstanceOverDestinationDirect, "aliasing-tlas-instance-over-blas-built-in-same-call", "aliasing",
            "a TLAS referencing BLAS b built in the same call as another BLAS created inside b's storage",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03706"}) {
  TogetherRig rig(device);
  rig.BuildTogether({&rig.overlap}, {&rig.b});
}

// Host builds read the instances when called; host instances hold handles.
struct HostTogether {
  Scene scene;
  TriangleInfos blas;
  SharedMemory memory;
  vkkit::Buffer storage;
  VkAccelerationStructureKHR twin;
  VkAccelerationStructureInstanceKHR instance{};
  VkAccelerationStructureGeometryKHR instances;
  VkAccelerationStructureBuildGeometryInfoKHR tlas;
  std::vector<unsigned char> host_scratch = std::vector<unsigned char>(1 << 16);
  explicit HostTogether(vkkit::Device& device)
      : scene(device), blas(scene, 1), memory(device, 1 << 16), storage(memory.Bind(0, 8192, kAsStorage)),
        instances(scene.Instances()) {
    const VkDeviceSize size = DriverSizes(device, blas.infos[0], {1}).accelerationStructureSize;
    blas.infos[0].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom);
    twin = memory.Structure(storage, 0, size, kBottom);
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    instance.mask = 0xff;
    instances.geometry.instances.data.hostAddress = &instance;
    tlas = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {instances});
    tlas.pGeometries = &instances;
    scene.Prepare(tlas, {1});
  }
  void Call(vkkit::Device& device) {
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos = blas.Host(blas.infos);
    infos.push_back(tlas);
    infos[1].scratchData.hostAddress = host_scratch.data();
    // The instance in mapped memory: without accelerationStructureHostCommands (lavapipe) asval reads a host
    // build's inputs only inside the app's mappings (layer/checks/host_reads.h).
    vkkit::Buffer mapped = device.CreateBuffer(sizeof(instance), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(mapped.mapped, &instance, sizeof(instance));
    instances.geometry.instances.data.hostAddress = mapped.mapped;
    CallHostBuild(device, infos, {&blas.range, &blas.range});
    instances.geometry.instances.data.hostAddress = &instance;
    device.Destroy(mapped);
  }
};

CORPUS_CASE(InstanceOfDestinationHost, "aliasing-host-tlas-instance-of-blas-built-in-same-call", "aliasing",
            "a host build of a BLAS and of a TLAS whose instance references that BLAS, in one call",
            {"VUID-vkBuildAccelerationStructuresKHR-None-03407",
             "VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03706", kHostFeature}) {
  HostTogether h(device);
  h.instance.accelerationStructureReference = reinterpret_cast<uint64_t>(h.blas.infos[0].dstAccelerationStructure);
  h.Call(device);
}

CORPUS_CASE(InstanceOverDestinationHost, "aliasing-host-tlas-instance-over-blas-built-in-same-call", "aliasing",
            "a host build of a BLAS and of a TLAS whose instance references another structure over that BLAS's bytes",
            {"VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03706", kHostFeature}) {
  HostTogether h(device);
  h.instance.accelerationStructureReference = reinterpret_cast<uint64_t>(h.twin);
  h.Call(device);
}

// ---- valid twins, built for real

CORPUS_CASE(ManyInfosSlicedScratch, "aliasing-valid-500-infos-sliced-scratch", "aliasing",
            "500 BLAS builds in one call: 128-byte aligned scratch slices of one buffer, destinations side by side "
            "in one storage buffer (256-byte stride)",
            {}) {
  Scene scene(device);
  constexpr uint32_t kInfos = 500;
  VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR prototype = Scene::Info(kBottom, {geometry});
  prototype.pGeometries = &geometry;
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, prototype, {1});
  const VkDeviceSize slice = RoundUp(sizes.buildScratchSize, 128);
  const VkDeviceSize stride = RoundUp(sizes.accelerationStructureSize, 256);
  vkkit::Buffer scratch = device.CreateBuffer(slice * kInfos, kStorage);
  vkkit::Buffer storage = device.CreateBuffer(stride * kInfos, kAsStorage);
  std::vector<VkAccelerationStructureKHR> structures;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(kInfos, prototype);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges(kInfos, &range);
  for (uint32_t i = 0; i < kInfos; ++i) {
    VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    create.buffer = storage.buffer;
    create.offset = stride * i;
    create.size = sizes.accelerationStructureSize;
    create.type = kBottom;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &create, nullptr, &as),
                 "vkCreateAccelerationStructureKHR");
    structures.push_back(as);
    infos[i].dstAccelerationStructure = as;
    infos[i].scratchData.deviceAddress = scratch.address + slice * i;
  }
  scene.BuildNow(infos, ranges);
  for (VkAccelerationStructureKHR as : structures) device.DestroyAccelerationStructureKHR(device.handle(), as, nullptr);
  device.Destroy(scratch);
  device.Destroy(storage);
}

CORPUS_CASE(InPlaceRefits, "aliasing-valid-in-place-refits", "aliasing",
            "3 BLASes built in one call, then refitted in place (src == dst) together in one call every frame", {}) {
  Scene scene(device);
  TriangleInfos builds(scene, 3);
  scene.BuildNow(builds.infos, builds.ranges);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> updates = builds.infos;
  for (auto& update : updates) {
    update.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    update.srcAccelerationStructure = update.dstAccelerationStructure;
  }
  for (int frame = 0; frame < 3; ++frame) scene.BuildNow(updates, builds.ranges);
}

CORPUS_CASE(SubAllocatedNeighbours, "aliasing-valid-suballocated-neighbours", "aliasing",
            "2 BLAS builds in one call whose scratch buffers and destinations are bound back to back in one "
            "VkDeviceMemory (touching, not overlapping)",
            {}) {
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, builds.infos[0], {1});
  SharedMemory memory(device, 1 << 16);
  const VkDeviceSize slice = RoundUp(sizes.buildScratchSize, 256);
  const VkDeviceSize stride = RoundUp(sizes.accelerationStructureSize, 256);
  vkkit::Buffer scratch_a = memory.Bind(256, slice, kStorage);
  vkkit::Buffer scratch_b = memory.Bind(256 + slice, slice, kStorage);
  vkkit::Buffer storage = memory.Bind(256 + 2 * slice, 2 * stride, kAsStorage);
  builds.infos[0].scratchData.deviceAddress = scratch_a.address;
  builds.infos[1].scratchData.deviceAddress = scratch_b.address;
  builds.infos[0].dstAccelerationStructure = memory.Structure(storage, 0, sizes.accelerationStructureSize, kBottom);
  builds.infos[1].dstAccelerationStructure = memory.Structure(storage, stride, sizes.accelerationStructureSize, kBottom);
  scene.BuildNow(builds.infos, builds.ranges);
}

CORPUS_CASE(RecreatedAtSameOffset, "aliasing-valid-structures-recreated-at-same-offset-every-frame", "aliasing",
            "a streaming loop: each frame the last frame's BLAS and its buffer are destroyed and a new buffer and BLAS "
            "are created at the same offset of one VkDeviceMemory (same addresses), then built in one call beside a "
            "persistent BLAS at the next offset",
            {}) {
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, builds.infos[0], {1});
  const VkDeviceSize stride = RoundUp(sizes.accelerationStructureSize, 256);
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer persistent_storage = memory.Bind(256 + stride, stride, kAsStorage);
  builds.infos[1].dstAccelerationStructure =
      memory.Structure(persistent_storage, 0, sizes.accelerationStructureSize, kBottom);
  for (int frame = 0; frame < 4; ++frame) {
    vkkit::Buffer storage = memory.Bind(256, stride, kAsStorage);
    const VkAccelerationStructureKHR streamed = memory.Structure(storage, 0, sizes.accelerationStructureSize, kBottom);
    builds.infos[0].dstAccelerationStructure = streamed;
    scene.BuildNow(builds.infos, builds.ranges);
    memory.DestroyStructure(streamed);
    memory.DestroyBuffer(storage);
  }
}

CORPUS_CASE(ScratchReusedAcrossCalls, "aliasing-valid-scratch-reused-across-calls", "aliasing",
            "one scratch buffer reused by every BLAS build, one build per vkCmdBuildAccelerationStructuresKHR with a "
            "barrier between them, as a streaming loader does",
            {}) {
  Scene scene(device);
  TriangleInfos builds(scene, 4);
  for (auto& info : builds.infos) info.scratchData = builds.infos[0].scratchData;
  device.OneShot([&](VkCommandBuffer cb) {
    for (size_t i = 0; i < builds.infos.size(); ++i) {
      device.CmdBuildAccelerationStructuresKHR(cb, 1, &builds.infos[i], &builds.ranges[i]);
      asval_test::BuildBarrier(cb);
    }
  });
}

CORPUS_CASE(TlasWithOtherBlasSameCall, "aliasing-valid-tlas-and-unrelated-blas-same-call", "aliasing",
            "a BLAS rebuilt in the same call as a TLAS whose instances reference only another, finished BLAS", {}) {
  TogetherRig rig(device);
  rig.BuildTogether({&rig.a}, {&rig.b, &rig.b});
}

}  // namespace
