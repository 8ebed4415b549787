// The build history without a driver: operation logs, application in order, the update rules over a
// hand-built DeviceState. Covers what lavapipe cannot run through the loader: indirect builds (counts on the
// device), host builds and host copies (valid twins; deferred completion), host serialization, and the
// store's undo, clobber and lost-operation behaviour.
#include <catch2/catch_test_macros.hpp>

#include <chrono>
#include <cstdio>
#include <cstring>

#include "build_command.h"
#include "copies.h"
#include "history_apply.h"
#include "history_record.h"
#include "history_submit.h"
#include "layer_settings.h"
#include "state_tracker.h"
#include "update_rules.h"
#include "vk_dispatch_table.h"

namespace asval {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeBufferAddress(VkDevice, const VkBufferDeviceAddressInfo* info) {
  return reinterpret_cast<uintptr_t>(info->buffer) * 0x100000;
}
VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeAsAddress(VkDevice, const VkAccelerationStructureDeviceAddressInfoKHR* info) {
  return reinterpret_cast<uintptr_t>(info->accelerationStructure) * 0x100;
}

constexpr uint32_t kAll = kCheckHistory | kCheckCopies;
const VkDeviceMemory kMemory = Fake<VkDeviceMemory>(1);

// A device with features on and structures 10, 11, 12 on buffers 2, 3, 4 of one memory (12 aliases 10).
struct World {
  DeviceState state;
  DeviceDispatchTable dispatch{};
  VkAccelerationStructureKHR a = Fake<VkAccelerationStructureKHR>(10);
  VkAccelerationStructureKHR b = Fake<VkAccelerationStructureKHR>(11);
  VkAccelerationStructureKHR alias_of_a = Fake<VkAccelerationStructureKHR>(12);

  World() {
    state.features.acceleration_structure = true;
    state.features.acceleration_structure_host_commands = true;
    state.features.acceleration_structure_indirect_build = true;
    dispatch.GetBufferDeviceAddress = &FakeBufferAddress;
    dispatch.GetAccelerationStructureDeviceAddressKHR = &FakeAsAddress;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, 1 << 24, 0};
    RecordAllocateMemory(state, alloc, kMemory);
    Structure(a, Fake<VkBuffer>(2), 0);
    Structure(b, Fake<VkBuffer>(3), 1 << 20);
    Structure(alias_of_a, Fake<VkBuffer>(4), 0);
  }
  void Structure(VkAccelerationStructureKHR as, VkBuffer buffer, VkDeviceSize memory_offset) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = 1 << 16;
    info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    RecordCreateBuffer(state, info, buffer);
    RecordBindBufferMemory(state, dispatch, Fake<VkDevice>(1), buffer, kMemory, memory_offset);
    VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    create.buffer = buffer;
    create.size = 1 << 16;
    create.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    RecordCreateAccelerationStructure(state, dispatch, Fake<VkDevice>(1), create, as);
  }
};

// One triangle geometry per count.
struct Build {
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = nullptr;

  Build(VkAccelerationStructureKHR dst, std::vector<uint32_t> counts, VkBuildAccelerationStructureFlagsKHR flags,
        VkAccelerationStructureKHR update_src = VK_NULL_HANDLE) {
    for (uint32_t count : counts) {
      VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
      g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
      g.geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      g.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
      g.geometry.triangles.maxVertex = 8;
      geometries.push_back(g);
      ranges.push_back(VkAccelerationStructureBuildRangeInfoKHR{count, 0, 0, 0});
    }
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.flags = flags;
    info.mode =
        update_src ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.srcAccelerationStructure = update_src;
    info.dstAccelerationStructure = dst;
    info.geometryCount = static_cast<uint32_t>(geometries.size());
    info.pGeometries = geometries.data();
    range_pointer = ranges.data();
  }
};

constexpr VkBuildAccelerationStructureFlagsKHR kUpdatable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;

OpOrigin Origin(OpCommand command) {
  OpOrigin o;
  o.command = command;
  o.ordinal = 1;
  o.command_buffer = command == OpCommand::kHostBuild ? VK_NULL_HANDLE : Fake<VkCommandBuffer>(77);
  return o;
}

// Checks then applies every operation of `batch`, like a submission; returns the VUIDs found.
std::vector<std::string> Execute(World& w, const OpBatch& batch, uint32_t enabled = kAll) {
  HistoryFindings findings;
  HistoryStore& store = w.state.history.store;
  auto lock = store.Lock();
  const HistoryCheckSite site{Location("vkQueueSubmit").Field("pSubmits", 0).Field("pCommandBuffers", 0),
                              Fake<VkCommandBuffer>(77), true};
  for (const AsOp& op : batch.ops()) {
    CheckOpHistory(w.state, store, enabled, batch, op, site, findings);
    ApplyOp(w.state, store, batch, op, nullptr);
  }
  std::vector<std::string> vuids;
  for (const HistoryFinding& f : findings.list()) vuids.push_back(f.vuid);
  return vuids;
}

OpBatch Builds(OpCommand command, std::initializer_list<const Build*> builds) {
  OpBatch batch;
  for (const Build* b : builds) {
    const bool indirect = command == OpCommand::kCmdBuildIndirect;
    batch.AppendBuilds(Origin(command), 1, &b->info, indirect ? nullptr : &b->range_pointer);
  }
  return batch;
}

TEST_CASE("history unit: indirect updates check everything but the primitive counts, and count that skip",
          "[history]") {
  World w;
  const Build build(w.a, {3, 4}, kUpdatable);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&build})).empty());
  const uint64_t skipped_before = w.state.history.store.rules_skipped_unknown_history.load();
  // Same shape, counts unknown (on the device): silent, two geometries' count checks skipped.
  const Build same(w.a, {9, 9}, kUpdatable, w.a);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuildIndirect, {&same})).empty());
  CHECK(w.state.history.store.rules_skipped_unknown_history.load() == skipped_before + 2);
  // A different geometry count is still found, under the indirect command's VUID.
  const Build three(w.a, {1, 1, 1}, kUpdatable, w.a);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuildIndirect, {&three})) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03758"});
  // And an indirect build's unknown counts do not make a later direct update with any count fail.
  const Build rebuilt(w.a, {5}, kUpdatable);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuildIndirect, {&rebuilt})).empty());
  const Build direct(w.a, {6}, kUpdatable, w.a);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&direct})).empty());
}

TEST_CASE("history unit: indirect updates of a source never built, or built without ALLOW_UPDATE, fire 03667",
          "[history]") {
  World w;
  const Build update(w.a, {1}, kUpdatable, w.a);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuildIndirect, {&update})) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03667"});
  const Build fixed(w.b, {1}, 0);
  const Build update_fixed(w.b, {1}, 0, w.b);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuildIndirect, {&fixed, &update_fixed})) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03667"});
}

TEST_CASE("history unit: host builds are checked when called (valid twin silent, mismatch reported)", "[history]") {
  World w;
  Reporter reporter(ReportSettings{});
  const CheckContext ctx{w.state, reporter, kAll};
  const Build build(w.a, {2}, kUpdatable);
  BuildCommand host{BuildCommandKind::kHostBuild, "vkBuildAccelerationStructuresKHR"};
  host.info_count = 1;
  host.infos = &build.info;
  host.ranges = &build.range_pointer;
  CHECK_FALSE(ValidateBuildHistory(ctx, host));
  FinishHostBuild(w.state, kAll, host, VK_SUCCESS);
  // Valid twin: an update repeating the host build.
  const Build update(w.a, {2}, kUpdatable, w.a);
  host.infos = &update.info;
  host.ranges = &update.range_pointer;
  CHECK_FALSE(ValidateBuildHistory(ctx, host));
  CHECK(reporter.ErrorCount() == 0);
  // Invalid: a different count (no messenger: reported to stderr, counted).
  const Build more(w.a, {3}, kUpdatable, w.a);
  host.infos = &more.info;
  host.ranges = &more.range_pointer;
  CHECK_FALSE(ValidateBuildHistory(ctx, host));
  CHECK(reporter.ErrorCount() == 1);
  // Device builds are left to submission.
  BuildCommand device{BuildCommandKind::kCmdBuild, "vkCmdBuildAccelerationStructuresKHR"};
  device.info_count = 1;
  device.infos = &more.info;
  device.ranges = &more.range_pointer;
  CHECK_FALSE(ValidateBuildHistory(ctx, device));
  CHECK(reporter.ErrorCount() == 1);
}

TEST_CASE("history unit: a deferred host build changes the history only once it completes successfully",
          "[history]") {
  World w;
  const VkDeferredOperationKHR deferred = Fake<VkDeferredOperationKHR>(5);
  const Build build(w.a, {1}, kUpdatable);
  BuildCommand host{BuildCommandKind::kHostBuild, "vkBuildAccelerationStructuresKHR"};
  host.deferred_operation = deferred;
  host.info_count = 1;
  host.infos = &build.info;
  host.ranges = &build.range_pointer;
  FinishHostBuild(w.state, kAll, host, VK_OPERATION_DEFERRED_KHR);
  {
    auto lock = w.state.history.store.Lock();
    CHECK(w.state.history.store.Get(w.a).kind == HistoryKind::kNeverBuilt);
  }
  CHECK(HasDeferredOps(w.state, deferred));
  CompleteDeferredOps(w.state, deferred, VK_SUCCESS);
  CHECK_FALSE(HasDeferredOps(w.state, deferred));
  auto lock = w.state.history.store.Lock();
  CHECK(w.state.history.store.Get(w.a).kind == HistoryKind::kBuilt);
  lock.unlock();
  // A failed deferred operation changes nothing.
  const Build other(w.b, {1}, kUpdatable);
  host.infos = &other.info;
  host.ranges = &other.range_pointer;
  FinishHostBuild(w.state, kAll, host, VK_OPERATION_DEFERRED_KHR);
  CompleteDeferredOps(w.state, deferred, VK_ERROR_OUT_OF_HOST_MEMORY);
  lock.lock();
  CHECK(w.state.history.store.Get(w.b).kind == HistoryKind::kNeverBuilt);
}

TEST_CASE("history unit: host copies and property writes are checked when called", "[history]") {
  World w;
  Reporter reporter(ReportSettings{});
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = w.a;
  copy.dst = w.b;
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR;
  CHECK_FALSE(CheckHostOps(w.state, reporter, kAll, HostCopyOps(copy), "vkCopyAccelerationStructureKHR"));
  CHECK(reporter.ErrorCount() == 1);  // src-04963: a never built
  const Build build(w.a, {1}, kUpdatable | VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&build})).empty());
  // Valid twins: the compaction of a compactable structure and its property query.
  CHECK_FALSE(CheckHostOps(w.state, reporter, kAll, HostCopyOps(copy), "vkCopyAccelerationStructureKHR"));
  const VkAccelerationStructureKHR structures[] = {w.a};
  const OpBatch query =
      HostWritePropertiesOps(1, structures, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR);
  CHECK_FALSE(CheckHostOps(w.state, reporter, kAll, query, "vkWriteAccelerationStructuresPropertiesKHR"));
  CHECK(reporter.ErrorCount() == 1);
  FinishHostOps(w.state, kAll, HostCopyOps(copy), VK_NULL_HANDLE, VK_SUCCESS);
  // The compacted copy updates like its source.
  const Build update(w.b, {1}, kUpdatable | VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR, w.b);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&update})).empty());
}

TEST_CASE("history unit: host serialization restores history only from unmodified bytes", "[history]") {
  World w;
  const Build build(w.a, {2}, kUpdatable);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&build})).empty());
  // Serialized bytes: a header whose total size (bytes 32..39) is the blob's length.
  std::vector<unsigned char> bytes(128, 0xab);
  const uint64_t total = bytes.size();
  std::memcpy(bytes.data() + 32, &total, sizeof(total));
  VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
  to.src = w.a;
  to.dst.hostAddress = bytes.data();
  to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
  FinishHostOps(w.state, kAll, HostCopyToMemoryOps(to), VK_NULL_HANDLE, VK_SUCCESS);
  VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  from.src.hostAddress = bytes.data();
  from.dst = w.b;
  from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
  FinishHostOps(w.state, kAll, HostCopyMemoryToOps(from), VK_NULL_HANDLE, VK_SUCCESS);
  const Build mismatch(w.b, {2, 2}, kUpdatable, w.b);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&mismatch})) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"});
  // The app rewrites the bytes (as when loading another blob into the same memory): unknown, silent, counted.
  bytes[100] ^= 1;
  FinishHostOps(w.state, kAll, HostCopyMemoryToOps(from), VK_NULL_HANDLE, VK_SUCCESS);
  const uint64_t skipped = w.state.history.store.rules_skipped_unknown_history.load();
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&mismatch})).empty());
  CHECK(w.state.history.store.rules_skipped_unknown_history.load() == skipped + 1);
}

TEST_CASE("history unit: a build over another structure's memory clobbers it; a rebuild clears that", "[history]") {
  World w;
  const Build a(w.a, {1}, kUpdatable), alias(w.alias_of_a, {1}, kUpdatable), b(w.b, {1}, kUpdatable);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&a, &b, &alias})).empty());
  const Build update_a(w.a, {1}, kUpdatable, w.a), update_b(w.b, {1}, kUpdatable, w.b);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&update_b, &update_a})) ==
        std::vector<std::string>{"ASVAL-History-Clobbered"});
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&a, &update_a})).empty());
  // Destroyed: the history ends; an update of a structure with the same handle finds it never built.
  ForgetHistory(w.state, w.a);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&update_a})) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667"});
}

TEST_CASE("history unit: undo restores what a skipped submission changed, but not later changes", "[history]") {
  World w;
  HistoryStore& store = w.state.history.store;
  const Build one(w.a, {1}, kUpdatable), two(w.a, {1, 1}, kUpdatable);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&one})).empty());
  const OpBatch batch = Builds(OpCommand::kCmdBuild, {&two, &one, &two});
  Transaction txn;
  {
    auto lock = store.Lock();
    for (const AsOp& op : batch.ops()) ApplyOp(w.state, store, batch, op, &txn);
    CHECK(store.Get(w.a).build->geometries.size() == 2);
    store.Undo(txn);
    CHECK(store.Get(w.a).build->geometries.size() == 1);  // three changes of one record, all undone
  }
  const Build three(w.a, {1, 1, 1}, kUpdatable);
  const OpBatch later = Builds(OpCommand::kCmdBuild, {&three});
  {
    auto lock = store.Lock();
    ApplyOp(w.state, store, batch, batch.ops()[0], &txn);    // ours: 2 geometries
    ApplyOp(w.state, store, later, later.ops()[0], nullptr);  // another thread's submission after ours: 3
    store.Undo(txn);
    CHECK(store.Get(w.a).build->geometries.size() == 3);  // the newer change stays
  }
}

TEST_CASE("history unit: a lost command buffer makes every history unknown", "[history]") {
  World w;
  Reporter reporter(ReportSettings{});
  const Build build(w.a, {1}, kUpdatable);
  CHECK(Execute(w, Builds(OpCommand::kCmdBuild, {&build})).empty());
  SubmitHistory submit(w.state, reporter, kAll);
  submit.Apply(Fake<VkCommandBuffer>(999), Location("vkQueueSubmit"));  // never seen allocated
  CHECK_FALSE(submit.Finish());
  auto lock = w.state.history.store.Lock();
  CHECK(w.state.history.store.Get(w.a).kind == HistoryKind::kUnknown);
  CHECK(w.state.history.store.Get(w.b).kind == HistoryKind::kUnknown);
}

TEST_CASE("history unit: command-buffer logs follow allocation, secondaries, resets and frees", "[history]") {
  World w;
  Reporter reporter(ReportSettings{});
  CommandBufferTracker& tracker = w.state.history.command_buffers;
  const VkCommandPool pool = Fake<VkCommandPool>(3);
  const VkCommandBuffer cbs[] = {Fake<VkCommandBuffer>(100), Fake<VkCommandBuffer>(101)};
  tracker.Allocate(pool, 2, cbs);
  const Build build(w.a, {1}, kUpdatable);
  BuildCommand cmd{BuildCommandKind::kCmdBuild, "vkCmdBuildAccelerationStructuresKHR"};
  cmd.command_buffer = cbs[1];  // the secondary
  cmd.info_count = 1;
  cmd.infos = &build.info;
  cmd.ranges = &build.range_pointer;
  RecordDeviceBuild(w.state, kAll, cmd);
  RecordExecuteCommands(w.state, kAll, cbs[0], 1, &cbs[1]);
  REQUIRE(tracker.Find(cbs[0])->batch.ops().size() == 1);
  CHECK(tracker.Find(cbs[0])->batch.ops()[0].origin.executed_by == cbs[0]);
  // Nothing is recorded when both history and copies are disabled.
  RecordDeviceBuild(w.state, kCheckAlignment, cmd);
  CHECK(tracker.Find(cbs[1])->batch.ops().size() == 1);
  tracker.ResetPool(pool);
  CHECK(tracker.Find(cbs[0])->batch.empty());
  tracker.Free(1, &cbs[0]);
  CHECK_FALSE(tracker.Find(cbs[0]));
  tracker.DestroyPool(pool);
  CHECK_FALSE(tracker.Find(cbs[1]));
  CHECK(tracker.size() == 0);
}

TEST_CASE("history unit: serialization sizes read back attach to the contents they were queried for", "[history]") {
  World w;
  const VkQueryPool pool = Fake<VkQueryPool>(8);
  const Build build(w.a, {1}, kUpdatable);
  OpBatch batch = Builds(OpCommand::kCmdBuild, {&build});
  AsOp query;
  query.kind = OpKind::kWriteProperties;
  query.dst = w.a;
  query.query_type = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR;
  query.query_pool = pool;
  query.query = 2;
  batch.Append(query);
  CHECK(Execute(w, batch).empty());
  // Results of queries 1..2, 64-bit with availability.
  const uint64_t results[4] = {0, 0, 4096, 1};
  RecordQueryResults(w.state, pool, 1, 2, sizeof(results), results, 16,
                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT, VK_SUCCESS);
  {
    auto lock = w.state.history.store.Lock();
    const AsHistory h = w.state.history.store.Get(w.a);
    CHECK(h.serialization_size == 4096);
    CHECK(h.serialization_size_generation == h.generation);
  }
  // Serializing into 4000 bytes: dst-03561.
  OpBatch serialize;
  AsOp op;
  op.kind = OpKind::kSerialize;
  op.src = w.a;
  op.copy_mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
  op.memory.capacity = 4000;
  serialize.Append(op);
  CHECK(Execute(w, serialize) ==
        std::vector<std::string>{"VUID-VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561"});
  op.memory.capacity = 4096;
  OpBatch enough;
  enough.Append(op);
  CHECK(Execute(w, enough).empty());
}

TEST_CASE("copies unit: host property queries and copies with valid arguments stay silent", "[copies]") {
  World w;
  Reporter reporter(ReportSettings{});
  const CheckContext ctx{w.state, reporter, kAll};
  const VkAccelerationStructureKHR structures[] = {w.a, w.b};
  for (VkQueryType type : {VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                           VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                           VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR,
                           VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR}) {
    CHECK_FALSE(ValidateWriteProperties(ctx, "vkWriteAccelerationStructuresPropertiesKHR", VK_NULL_HANDLE, 2,
                                        structures, type, VK_NULL_HANDLE, 0));
  }
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = w.a;
  copy.dst = w.b;
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  CHECK_FALSE(ValidateCopyInfo(ctx, "vkCopyAccelerationStructureKHR", VK_NULL_HANDLE, copy));
  CHECK(reporter.ErrorCount() == 0);
  // The host command's type rule fires like the device command's (no messenger: stderr, counted).
  CHECK_FALSE(ValidateWriteProperties(ctx, "vkWriteAccelerationStructuresPropertiesKHR", VK_NULL_HANDLE, 2,
                                      structures, VK_QUERY_TYPE_OCCLUSION, VK_NULL_HANDLE, 0));
  CHECK(reporter.ErrorCount() == 1);
  // Structures over the same memory: dst-07791 for the host copy too.
  copy.dst = w.alias_of_a;
  CHECK_FALSE(ValidateCopyInfo(ctx, "vkCopyAccelerationStructureKHR", VK_NULL_HANDLE, copy));
  CHECK(reporter.ErrorCount() == 2);
}

// Not run by default ([.]): the submission-time cost behind docs/performance.md. Run it alone, optionally
// under callgrind with --toggle-collect='*SubmitHistory*' to count only the layer's submission work:
//   asval_unit_tests "[.history-bench]"
TEST_CASE("history bench: operations applied per second at submission", "[.history-bench]") {
  struct Scenario {
    const char* name;
    uint32_t structures;  // one operation per structure per submission
    bool update;          // steady-state frames update; start-up builds
    uint32_t submissions;
  };
  for (const Scenario& sc : {Scenario{"per-frame updates of 64 BLASes", 64, true, 2000},
                             Scenario{"start-up batch of 2000 builds", 2000, false, 50},
                             Scenario{"command buffer without AS operations", 0, true, 100000}}) {
    World w;
    std::vector<VkAccelerationStructureKHR> handles;
    for (uint32_t i = 0; i < sc.structures; ++i) {
      handles.push_back(Fake<VkAccelerationStructureKHR>(1000 + i));
      w.Structure(handles.back(), Fake<VkBuffer>(5000 + i), (VkDeviceSize{1} << 16) * (i + 32));
    }
    Reporter reporter(ReportSettings{});
    const VkCommandPool pool = Fake<VkCommandPool>(3);
    const VkCommandBuffer cb = Fake<VkCommandBuffer>(100);
    w.state.history.command_buffers.Allocate(pool, 1, &cb);
    std::vector<Build> builds;
    builds.reserve(sc.structures * 2);
    for (VkAccelerationStructureKHR as : handles) builds.emplace_back(as, std::vector<uint32_t>{4, 4}, kUpdatable);
    BuildCommand cmd{BuildCommandKind::kCmdBuild, "vkCmdBuildAccelerationStructuresKHR"};
    cmd.command_buffer = cb;
    for (const Build& b : builds) {  // the first build of each, so that updates have a source
      cmd.info_count = 1;
      cmd.infos = &b.info;
      cmd.ranges = &b.range_pointer;
      RecordDeviceBuild(w.state, kAll, cmd);
    }
    {
      SubmitHistory first(w.state, reporter, kAll);
      first.Apply(cb, Location("vkQueueSubmit"));
      REQUIRE_FALSE(first.Finish());
    }
    if (sc.update) {
      ResetCommandBufferLog(w.state, cb);
      const size_t count = builds.size();
      for (size_t i = 0; i < count; ++i) {
        builds.emplace_back(handles[i], std::vector<uint32_t>{4, 4}, kUpdatable, handles[i]);
      }
      for (size_t i = count; i < builds.size(); ++i) {
        cmd.infos = &builds[i].info;
        cmd.ranges = &builds[i].range_pointer;
        RecordDeviceBuild(w.state, kAll, cmd);
      }
    }
    const auto start = std::chrono::steady_clock::now();
    uint64_t ops = 0;
    for (uint32_t s = 0; s < sc.submissions; ++s) {
      SubmitHistory submit(w.state, reporter, kAll);
      submit.Apply(cb, Location("vkQueueSubmit"));
      REQUIRE_FALSE(submit.Finish());
      ops += submit.ops_applied();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%s: %u submissions, %llu operations, %.0f ns per submission, %.2f M operations/s\n", sc.name,
                sc.submissions, static_cast<unsigned long long>(ops), seconds * 1e9 / sc.submissions,
                ops ? ops / seconds / 1e6 : 0.0);
    CHECK(reporter.ErrorCount() == 0);
  }
}

}  // namespace
}  // namespace asval
