// The per-thread memos of the build hot path that outlive one command: the structure memo of the checks
// (checks/structure_memo.h) and the recorder's last command buffer (state/history_recorder.cpp). Each must
// answer exactly what the shadow maps answer now, never what they answered before a structure or command
// buffer was created, destroyed or freed, nor what another device's maps answered.
#include <catch2/catch_test_macros.hpp>

#include <memory>

#include "history_recorder.h"
#include "state_tracker.h"
#include "structure_memo.h"
#include "vk_dispatch_table.h"

namespace asval {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

void CreateStructure(DeviceState& state, uintptr_t n, VkDeviceSize size) {
  const DeviceDispatchTable dispatch{};
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = Fake<VkBuffer>(1);
  info.size = size;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  RecordCreateAccelerationStructure(state, dispatch, Fake<VkDevice>(1), info, Fake<VkAccelerationStructureKHR>(n));
}

const AccelerationStructureState* Lookup(StructureMemo& memo, const DeviceState& state, uintptr_t n) {
  std::shared_ptr<const AccelerationStructureState> hold;
  return memo.Find(state, Fake<VkAccelerationStructureKHR>(n), hold);
}

TEST_CASE("structure memo: a destroyed or recreated structure is seen as it is now", "[memo]") {
  DeviceState state;
  CreateStructure(state, 7, 256);
  StructureMemo memo;
  memo.Sync(state);
  REQUIRE(Lookup(memo, state, 7));
  CHECK(Lookup(memo, state, 7)->size == 256);
  CHECK_FALSE(Lookup(memo, state, 8));  // not a structure: memoized as such

  RecordDestroyAccelerationStructure(state, Fake<VkAccelerationStructureKHR>(7));
  memo.Sync(state);  // the next command
  CHECK_FALSE(Lookup(memo, state, 7));

  CreateStructure(state, 7, 512);  // the same handle value again
  CreateStructure(state, 8, 64);
  memo.Sync(state);
  REQUIRE(Lookup(memo, state, 7));
  CHECK(Lookup(memo, state, 7)->size == 512);
  REQUIRE(Lookup(memo, state, 8));
  CHECK(Lookup(memo, state, 8)->size == 64);
}

TEST_CASE("structure memo: a record handed out stays valid for the command", "[memo]") {
  DeviceState state;
  CreateStructure(state, 7, 256);
  StructureMemo memo;
  memo.Sync(state);
  const AccelerationStructureState* record = Lookup(memo, state, 7);
  REQUIRE(record);
  // Another thread destroys it meanwhile (an app bug, but not a crash of the layer): the memo still holds it.
  RecordDestroyAccelerationStructure(state, Fake<VkAccelerationStructureKHR>(7));
  CHECK(record->size == 256);
  CHECK(Lookup(memo, state, 7) == record);  // the same command still sees what it saw
}

TEST_CASE("structure memo: many structures, and answers of one device are not given for another", "[memo]") {
  StructureMemo memo;
  {
    DeviceState first;
    for (uintptr_t n = 1; n <= 300; ++n) CreateStructure(first, n, n);
    memo.Sync(first);
    // More structures than slots: colliding lookups are held by the caller, every answer is right.
    for (uintptr_t n = 1; n <= 300; ++n) {
      std::shared_ptr<const AccelerationStructureState> hold;
      const AccelerationStructureState* record = memo.Find(first, Fake<VkAccelerationStructureKHR>(n), hold);
      REQUIRE(record);
      CHECK(record->size == n);
    }
  }
  DeviceState second;  // may live where the first one did; its map is unchanged since creation
  memo.Sync(second);
  CHECK_FALSE(Lookup(memo, second, 5));
}

// Builds recorded into `cb` so far.
std::size_t RecordedBuilds(DeviceState& state, VkCommandBuffer cb) {
  state.command_buffers.End(cb);
  const std::shared_ptr<CommandBufferState> found = state.command_buffers.Find(cb);
  REQUIRE(found);
  const std::shared_ptr<const RecordedOps> ops = found->Executable();
  return ops ? ops->batch.ops().size() : 0;
}

TEST_CASE("recorder: a freed command buffer's handle, allocated again, records into the new command buffer",
          "[memo]") {
  DeviceState state;
  state.history_tracked = true;
  const VkCommandPool pool = Fake<VkCommandPool>(3);
  const VkCommandBuffer cb = Fake<VkCommandBuffer>(0x40);
  const VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, pool,
                                             VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1};
  state.command_buffers.CreatePool(pool, 0);
  state.command_buffers.Allocate(allocate, &cb);

  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  info.dstAccelerationStructure = Fake<VkAccelerationStructureKHR>(9);
  RecordCmdBuild(state, cb, OpCommand::kCmdBuild, 1, &info, nullptr);
  RecordCmdBuild(state, cb, OpCommand::kCmdBuild, 1, &info, nullptr);  // the remembered command buffer
  CHECK(RecordedBuilds(state, cb) == 2);

  state.command_buffers.Free(1, &cb);
  RecordCmdBuild(state, cb, OpCommand::kCmdBuild, 1, &info, nullptr);  // not a command buffer now: nothing
  CHECK_FALSE(state.command_buffers.Find(cb));

  state.command_buffers.Allocate(allocate, &cb);  // the same handle value, a new command buffer
  RecordCmdBuild(state, cb, OpCommand::kCmdBuild, 1, &info, nullptr);
  CHECK(RecordedBuilds(state, cb) == 1);
}

}  // namespace
}  // namespace asval
