// Hot-path shortcuts of the build checks. The per-thread buffer memo (checks/buffer_memo.h), kept from one
// build command to the next, must answer exactly what the shadow maps answer now, never what they answered
// before a buffer was created, bound or destroyed, nor what another device's maps answered. The size
// shortcut (SameSignatureArrays) may only fire when the signature cannot differ.
#include <catch2/catch_test_macros.hpp>

#include <memory>
#include <optional>
#include <vector>

#include "buffer_memo.h"
#include "build_sizes.h"
#include "state_tracker.h"
#include "vk_dispatch_table.h"

namespace asval {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

// Buffer n lives at address n * 0x10000.
VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeBufferAddress(VkDevice, const VkBufferDeviceAddressInfo* info) {
  return reinterpret_cast<uintptr_t>(info->buffer) * 0x10000;
}

constexpr VkBufferUsageFlags kInput =
    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

void AddBoundBuffer(DeviceState& state, uintptr_t n, VkBufferUsageFlags usage) {
  DeviceDispatchTable dispatch{};
  dispatch.GetBufferDeviceAddress = &FakeBufferAddress;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = 4096;
  info.usage = usage;
  RecordCreateBuffer(state, info, Fake<VkBuffer>(n));
  RecordBindBufferMemory(state, dispatch, Fake<VkDevice>(1), Fake<VkBuffer>(n), Fake<VkDeviceMemory>(100), 0);
}

TEST_CASE("buffer memo: a destroyed buffer is not found by the next command", "[memo]") {
  DeviceState state;
  AddBoundBuffer(state, 2, kInput);
  BufferMemo memo;
  memo.Sync(state);
  REQUIRE(memo.Held(state, 0x20000, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR));
  KnownBuffer found;
  REQUIRE(memo.Find(state, Fake<VkBuffer>(2), &found));

  RecordDestroyBuffer(state, Fake<VkBuffer>(2));
  memo.Sync(state);  // the next command
  CHECK_FALSE(memo.Held(state, 0x20000, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR));
  CHECK_FALSE(memo.Find(state, Fake<VkBuffer>(2), &found));
}

TEST_CASE("buffer memo: a recreated handle is seen with its new usage", "[memo]") {
  DeviceState state;
  AddBoundBuffer(state, 2, kInput);
  BufferMemo memo;
  memo.Sync(state);
  REQUIRE(memo.Held(state, 0x20000, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR));

  RecordDestroyBuffer(state, Fake<VkBuffer>(2));
  AddBoundBuffer(state, 2, VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);  // same handle and address, no input usage
  memo.Sync(state);
  CHECK_FALSE(memo.Held(state, 0x20000, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR));
  CHECK(memo.Held(state, 0x20000, 64, VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT));
}

TEST_CASE("buffer memo: answers of one device are not given for another", "[memo]") {
  BufferMemo memo;
  {
    DeviceState first;
    AddBoundBuffer(first, 2, kInput);
    memo.Sync(first);
    REQUIRE(memo.Held(first, 0x20000, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR));
  }
  DeviceState second;  // may live where the first one did; its maps are unchanged since creation
  memo.Sync(second);
  CHECK_FALSE(memo.Held(second, 0x20000, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR));
}

TEST_CASE("buffer memo: unchanged maps keep the entries from one command to the next", "[memo]") {
  DeviceState state;
  AddBoundBuffer(state, 2, kInput);
  BufferMemo memo;
  memo.Sync(state);
  const KnownBuffer* held =
      memo.Held(state, 0x20000, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  REQUIRE(held);
  const StampValue before = state.buffers.stamp();
  memo.Sync(state);
  CHECK(state.buffers.stamp() == before);
  // The same entry answers (no map lookup): its address in the memo did not move.
  CHECK(memo.Held(state, 0x20100, 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR) == held);
  // Any change to the buffer map is a new stamp.
  AddBoundBuffer(state, 3, kInput);
  CHECK(state.buffers.stamp() != before);
}

TEST_CASE("buffer memo: a command over 40 buffers keeps every one from one command to the next", "[memo]") {
  // 16 infos, each with its own scratch and vertex buffer, plus their destinations' buffers: more buffers than
  // the memo once held (32, replaced round-robin, so that every lookup of such a call missed). Each buffer must
  // still be answered by the entry it got on the first command (the same address in the memo: no map lookup).
  DeviceState state;
  constexpr uintptr_t kBuffers = 40;
  for (uintptr_t n = 1; n <= kBuffers; ++n) AddBoundBuffer(state, n, kInput);
  BufferMemo memo;
  std::vector<const KnownBuffer*> first;
  for (int command = 0; command < 2; ++command) {
    memo.Sync(state);
    for (uintptr_t n = 1; n <= kBuffers; ++n) {
      const KnownBuffer* held =
          memo.Held(state, n * 0x10000 + 16, 64, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
      REQUIRE(held);
      CHECK(held->buffer == Fake<VkBuffer>(n));
      if (command == 0) {
        first.push_back(held);
      } else {
        CHECK(held == first[n - 1]);
      }
    }
  }
  // Found by handle, the answers agree with the shadow state.
  for (uintptr_t n = 1; n <= kBuffers; ++n) {
    KnownBuffer found;
    REQUIRE(memo.Find(state, Fake<VkBuffer>(n), &found));
    CHECK(found.base == n * 0x10000);
    CHECK(found.memory == Fake<VkDeviceMemory>(100));
  }
}

TEST_CASE("buffer memo: a hint from an earlier command never answers for another buffer", "[memo]") {
  DeviceState state;
  AddBoundBuffer(state, 2, kInput | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  AddBoundBuffer(state, 3, kInput | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  BufferMemo memo;
  memo.Sync(state);
  uint8_t hint = 200;  // anything at first
  KnownBuffer found;
  REQUIRE(memo.HoldingHinted(state, 0x20000, 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, hint, &found));
  CHECK(found.buffer == Fake<VkBuffer>(2));
  // The same place now reads buffer 3: the hint (buffer 2's entry) does not serve, the answer is right.
  REQUIRE(memo.HoldingHinted(state, 0x30000, 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, hint, &found));
  CHECK(found.buffer == Fake<VkBuffer>(3));
  // Nor for a usage the buffer lacks.
  CHECK_FALSE(memo.HoldingHinted(state, 0x30000, 64, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, hint, &found));

  // A structure on buffer 3, looked up through a hint that names buffer 2's entry.
  const std::optional<std::shared_ptr<const BufferState>> three = state.buffers.find(Fake<VkBuffer>(3));
  REQUIRE(three);
  AccelerationStructureState structure;
  structure.buffer = Fake<VkBuffer>(3);
  structure.buffer_id = (*three)->id;
  uint8_t dst_hint = 0;
  REQUIRE(memo.FindOfStructureHinted(state, structure, dst_hint, &found));
  CHECK(found.buffer == Fake<VkBuffer>(3));
  REQUIRE(memo.FindOfStructureHinted(state, structure, dst_hint, &found));  // through the hint now
  CHECK(found.buffer == Fake<VkBuffer>(3));

  // Buffer 3 destroyed and recreated with its handle: the next command's memo is empty, and the structure's
  // buffer (the old one, by identity) is not found through the stale hint.
  RecordDestroyBuffer(state, Fake<VkBuffer>(3));
  AddBoundBuffer(state, 3, kInput);
  memo.Sync(state);
  CHECK_FALSE(memo.FindOfStructureHinted(state, structure, dst_hint, &found));
}

}  // namespace
}  // namespace asval

// The per-call shortcut of the size lookup (build_memory_pass.cpp): pInfos[i] reuses pInfos[i - 1]'s sizes only
// when the two certainly have the same signature.
namespace asval {
namespace {

TEST_CASE("size shortcut: only the very same geometry and count arrays share sizes", "[memo]") {
  VkAccelerationStructureGeometryKHR geometries[2]{};
  VkAccelerationStructureBuildRangeInfoKHR ranges_a[2]{{3, 0, 0, 0}, {3, 0, 0, 0}};
  VkAccelerationStructureBuildRangeInfoKHR ranges_b[2]{{3, 0, 0, 0}, {3, 0, 0, 0}};  // equal values, other array
  VkAccelerationStructureBuildGeometryInfoKHR infos[2]{};
  for (VkAccelerationStructureBuildGeometryInfoKHR& info : infos) {
    info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.geometryCount = 2;
    info.pGeometries = geometries;
  }
  const VkAccelerationStructureBuildRangeInfoKHR* ranges[2] = {ranges_a, ranges_a};
  BuildCommand cmd{BuildCommandKind::kCmdBuild, "vkCmdBuildAccelerationStructuresKHR"};
  cmd.info_count = 2;
  cmd.infos = infos;
  cmd.ranges = ranges;
  CHECK(SameSignatureArrays(cmd, 0, 1));

  ranges[1] = ranges_b;  // the counts could differ: read them
  CHECK_FALSE(SameSignatureArrays(cmd, 0, 1));
  ranges[1] = ranges_a;

  infos[1].flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  CHECK_FALSE(SameSignatureArrays(cmd, 0, 1));
  infos[1].flags = 0;

  infos[1].geometryCount = 1;
  CHECK_FALSE(SameSignatureArrays(cmd, 0, 1));
  infos[1].geometryCount = 2;

  const VkAccelerationStructureGeometryKHR* pointers[2] = {&geometries[0], &geometries[1]};
  infos[1].pGeometries = nullptr;
  infos[1].ppGeometries = pointers;
  CHECK_FALSE(SameSignatureArrays(cmd, 0, 1));
  infos[1].ppGeometries = nullptr;
  infos[1].pGeometries = geometries;

  VkBaseInStructure chained{VK_STRUCTURE_TYPE_APPLICATION_INFO, nullptr};  // any extension structure
  infos[0].pNext = &chained;
  infos[1].pNext = &chained;
  CHECK_FALSE(SameSignatureArrays(cmd, 0, 1));  // an extension could change the sizes: never shortcut
}

}  // namespace
}  // namespace asval
