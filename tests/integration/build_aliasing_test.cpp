// Family "aliasing": memory one build of a command writes is not read or written by another build of the same
// command, compared over the bytes the driver says each build touches, in VkDeviceMemory offsets; with the
// valid twins of real programs (thousands of infos sharing one scratch buffer, in-place updates,
// sub-allocation). Negative tests narrow enabled_checks to the family.
#include <catch2/catch_test_macros.hpp>
#include <catch2/generators/catch_generators.hpp>
#include <cstring>

#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
constexpr VkBufferUsageFlags kAsStorage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;

constexpr PerCommand kScratchScratch = {"VUID-vkCmdBuildAccelerationStructuresKHR-scratchData-03704",
                                        "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-scratchData-03704",
                                        "VUID-vkBuildAccelerationStructuresKHR-scratchData-03704"};
constexpr PerCommand kDstDst = {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03702",
                                "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03702",
                                "VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03702"};
constexpr PerCommand kDstScratch = {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03703",
                                    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03703",
                                    nullptr};
constexpr PerCommand kScratchSrc = {"VUID-vkCmdBuildAccelerationStructuresKHR-scratchData-03705",
                                    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-scratchData-03705", nullptr};
constexpr PerCommand kDstSrc = {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03701",
                                "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03701",
                                "VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03701"};
constexpr PerCommand kUpdateAlias = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03668",
                                     "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03668",
                                     "VUID-vkBuildAccelerationStructuresKHR-pInfos-03668"};

// n one-triangle bottom-level infos over the scene's vertices, each with its own destination and scratch.
struct TriangleInfos {
  VkAccelerationStructureGeometryKHR geometry;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges;
  TriangleInfos(Scene& scene, size_t n) : geometry(scene.Triangles()) {
    for (size_t i = 0; i < n; ++i) {
      infos.push_back(Scene::Info(kBottom, {geometry}));
      infos.back().pGeometries = &geometry;
      scene.Prepare(infos.back(), {1});
      ranges.push_back(&range);
    }
  }
};

TEST_CASE("scratchData-03704: two infos whose scratch shares bytes are reported, for the three commands",
          "[integration][aliasing][03704]") {
  CheckFixture f("aliasing");
  vkkit::Device& device = f.device();
  Scene scene(device);
  TriangleInfos builds(scene, 3);
  // Half a MiB apart: far more than any driver's host scratch for one triangle (lavapipe's is a few
  // hundred bytes, larger drivers' a few KiB), so only infos 1 and 2 share.
  std::vector<unsigned char> host_scratch(1 << 20);
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos = builds.infos;
    if (command == Command::kHost) {
      for (auto& info : infos) info.scratchData.hostAddress = host_scratch.data() + (1 << 19);
      infos[0].scratchData.hostAddress = host_scratch.data();
    }
    infos[2].scratchData = infos[1].scratchData;  // infos 1 and 2 share; info 0 stays apart
    f.monitor().Expect(kScratchScratch.For(command));
    IssueWithRealRanges(device, command, infos, builds.ranges);
    const std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].id_name == kScratchScratch.For(command));
    CHECK(messages[0].text.find("pInfos[1].scratchData") != std::string::npos);
    CHECK(messages[0].text.find("pInfos[2].scratchData") != std::string::npos);
  }
}

TEST_CASE("scratchData-03704: scratch in two different buffers over one VkDeviceMemory is compared in memory",
          "[integration][aliasing][03704]") {
  CheckFixture f("aliasing");
  vkkit::Device& device = f.device();
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  const VkDeviceSize scratch = DriverSizes(device, builds.infos[0], {1}).buildScratchSize;
  REQUIRE(scratch > 32);
  SharedMemory memory(device, 1 << 16);
  // Buffer b starts 64 bytes into buffer a's memory: a's bytes [32, 32 + scratch) and b's first bytes overlap.
  vkkit::Buffer a = memory.Bind(0, 4096, kStorage);
  vkkit::Buffer b = memory.Bind(64, 4096, kStorage);
  builds.infos[0].scratchData.deviceAddress = a.address + 32;
  builds.infos[1].scratchData.deviceAddress = b.address;
  f.monitor().Expect(kScratchScratch.direct);
  IssueWithRealRanges(device, Command::kDirect, builds.infos, builds.ranges);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("dstAccelerationStructure-03702: two destinations over the same memory, for the three commands",
          "[integration][aliasing][03702]") {
  CheckFixture f("aliasing");
  vkkit::Device& device = f.device();
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  const VkDeviceSize size = DriverSizes(device, builds.infos[0], {1}).accelerationStructureSize;
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer storage = memory.Bind(0, 8192, kAsStorage);
  const Command command = GENERATE(Command::kDirect, Command::kIndirect, Command::kHost);
  INFO(CommandName(command));
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos = builds.infos;
  // Two structures at the same offset of one buffer (distinct handles: dstAccelerationStructure-03698 is
  // the handles family's).
  infos[0].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom);
  infos[1].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom);
  f.monitor().Expect(kDstDst.For(command));
  IssueWithRealRanges(device, command, infos, builds.ranges);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("dstAccelerationStructure-03703: a destination over its own scratch", "[integration][aliasing][03703]") {
  CheckFixture f("aliasing");
  vkkit::Device& device = f.device();
  Scene scene(device);
  TriangleInfos builds(scene, 1);
  const VkDeviceSize size = DriverSizes(device, builds.infos[0], {1}).accelerationStructureSize;
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer storage = memory.Bind(0, 8192, kAsStorage | kStorage);
  const Command command = GENERATE(Command::kDirect, Command::kIndirect);
  INFO(CommandName(command));
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos = builds.infos;
  infos[0].dstAccelerationStructure = memory.Structure(storage, 1024, size, kBottom);
  infos[0].scratchData.deviceAddress = storage.address + 1024;
  f.monitor().Expect(kDstScratch.For(command));
  IssueWithRealRanges(device, command, infos, builds.ranges);
  CHECK(f.monitor().Verify() == "");
}

// infos[0] updates `source` (at offset 0 of a shared buffer) into its own destination; infos[1] is a build.
struct UpdateOverShared {
  Scene scene;
  TriangleInfos builds;
  VkDeviceSize size;
  SharedMemory memory;
  vkkit::Buffer storage;
  VkAccelerationStructureKHR source;
  explicit UpdateOverShared(vkkit::Device& device)
      : scene(device),
        builds(scene, 2),
        size(DriverSizes(device, builds.infos[0], {1}).accelerationStructureSize),
        memory(device, 1 << 16),
        storage(memory.Bind(0, 8192, kAsStorage | kStorage)),
        source(memory.Structure(storage, 0, size, kBottom)) {
    builds.infos[0].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    builds.infos[0].srcAccelerationStructure = source;
  }
};

TEST_CASE("scratchData-03705: another info's scratch over an update's source", "[integration][aliasing][03705]") {
  CheckFixture f("aliasing");
  UpdateOverShared u(f.device());
  const Command command = GENERATE(Command::kDirect, Command::kIndirect);
  INFO(CommandName(command));
  u.builds.infos[1].scratchData.deviceAddress = u.storage.address + 64;
  f.monitor().Expect(kScratchSrc.For(command));
  IssueWithRealRanges(f.device(), command, u.builds.infos, u.builds.ranges);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("dstAccelerationStructure-03701 / pInfos-03668: destinations over an update's source, for the three "
          "commands",
          "[integration][aliasing][03701][03668]") {
  CheckFixture f("aliasing");
  UpdateOverShared u(f.device());
  const Command command = GENERATE(Command::kDirect, Command::kIndirect, Command::kHost);
  INFO(CommandName(command));
  SECTION("03701: another info's destination over the source") {
    u.builds.infos[1].dstAccelerationStructure = u.memory.Structure(u.storage, 0, u.size, kBottom);
    f.monitor().Expect(kDstSrc.For(command));
  }
  SECTION("03668: the update's own destination is another structure over the source's memory") {
    u.builds.infos[0].dstAccelerationStructure = u.memory.Structure(u.storage, 0, u.size, kBottom);
    f.monitor().Expect(kUpdateAlias.For(command));
  }
  IssueWithRealRanges(f.device(), command, u.builds.infos, u.builds.ranges);
  CHECK(f.monitor().Verify() == "");
}

// Host builds read their instances when called: a TLAS instance that references another info's
// destination, or a structure over that destination's memory.
TEST_CASE("None-03407 / dstAccelerationStructure-03706: host-build instances referencing what another info writes",
          "[integration][aliasing][03407][03706]") {
  CheckFixture f("aliasing");
  vkkit::Device& device = f.device();
  Scene scene(device);
  TriangleInfos blas(scene, 1);
  const VkDeviceSize size = DriverSizes(device, blas.infos[0], {1}).accelerationStructureSize;
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer storage = memory.Bind(0, 8192, kAsStorage);
  blas.infos[0].dstAccelerationStructure = memory.Structure(storage, 0, size, kBottom);
  const VkAccelerationStructureKHR twin = memory.Structure(storage, 0, size, kBottom);  // same bytes, other handle
  std::vector<unsigned char> host_scratch(1 << 16);
  // The instance in mapped memory: without accelerationStructureHostCommands (lavapipe) the layer reads a host
  // build's inputs only inside the app's mappings (layer/checks/host_reads.h).
  vkkit::Buffer instance_memory =
      device.CreateBuffer(sizeof(VkAccelerationStructureInstanceKHR), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  auto& instance = *static_cast<VkAccelerationStructureInstanceKHR*>(instance_memory.mapped);
  instance = VkAccelerationStructureInstanceKHR{};
  instance.mask = 0xff;
  VkAccelerationStructureGeometryKHR instances = scene.Instances();
  instances.geometry.instances.data.hostAddress = &instance;
  VkAccelerationStructureBuildGeometryInfoKHR tlas =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {instances});
  tlas.pGeometries = &instances;
  scene.Prepare(tlas, {1});
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos = {blas.infos[0], tlas};
  infos[0].scratchData.hostAddress = host_scratch.data();
  infos[1].scratchData.hostAddress = host_scratch.data() + 32768;
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  SECTION("None-03407 (and 03706): the instance references the BLAS this command builds") {
    instance.accelerationStructureReference = reinterpret_cast<uint64_t>(blas.infos[0].dstAccelerationStructure);
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-None-03407");
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03706");
  }
  SECTION("03706: the instance references another structure over the same memory") {
    instance.accelerationStructureReference = reinterpret_cast<uint64_t>(twin);
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03706");
  }
  CallHostBuild(device, infos, {&range, &range});
  CHECK(f.monitor().Verify() == "");
  device.Destroy(instance_memory);
}

// ---- valid twins: every family on, built for real on lavapipe

TEST_CASE("aliasing valid twin: 2000 infos in one call, 128-byte scratch slices of one buffer, sub-allocated "
          "destinations",
          "[integration][aliasing][valid]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  Scene scene(device);
  constexpr uint32_t kInfos = 2000;
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
    REQUIRE(device.CreateAccelerationStructureKHR(device.handle(), &create, nullptr, &as) == VK_SUCCESS);
    structures.push_back(as);
    infos[i].dstAccelerationStructure = as;
    infos[i].scratchData.deviceAddress = scratch.address + slice * i;
  }
  scene.BuildNow(infos, ranges);
  CHECK(f.monitor().Verify() == "");
  for (VkAccelerationStructureKHR as : structures) device.DestroyAccelerationStructureKHR(device.handle(), as, nullptr);
  device.Destroy(scratch);
  device.Destroy(storage);
}

TEST_CASE("aliasing valid twin: in-place updates (src == dst) of several structures every frame",
          "[integration][aliasing][valid]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  Scene scene(device);
  TriangleInfos builds(scene, 3);
  scene.BuildNow(builds.infos, builds.ranges);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> updates = builds.infos;
  for (auto& update : updates) {
    update.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    update.srcAccelerationStructure = update.dstAccelerationStructure;
  }
  for (int frame = 0; frame < 3; ++frame) {
    INFO("frame " << frame);
    scene.BuildNow(updates, builds.ranges);
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("aliasing valid twin: scratch and destinations in buffers sharing one VkDeviceMemory at different offsets",
          "[integration][aliasing][valid]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  Scene scene(device);
  TriangleInfos builds(scene, 2);
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, builds.infos[0], {1});
  SharedMemory memory(device, 1 << 16);
  const VkDeviceSize slice = RoundUp(sizes.buildScratchSize, 256);
  const VkDeviceSize stride = RoundUp(sizes.accelerationStructureSize, 256);
  vkkit::Buffer scratch_a = memory.Bind(0, slice, kStorage);
  vkkit::Buffer scratch_b = memory.Bind(slice, slice, kStorage);
  vkkit::Buffer storage = memory.Bind(2 * slice, 2 * stride, kAsStorage);
  builds.infos[0].scratchData.deviceAddress = scratch_a.address;
  builds.infos[1].scratchData.deviceAddress = scratch_b.address;
  builds.infos[0].dstAccelerationStructure = memory.Structure(storage, 0, sizes.accelerationStructureSize, kBottom);
  builds.infos[1].dstAccelerationStructure = memory.Structure(storage, stride, sizes.accelerationStructureSize, kBottom);
  scene.BuildNow(builds.infos, builds.ranges);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
