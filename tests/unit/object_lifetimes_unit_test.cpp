// Issue 29 (family lifetime, family traces): what the layer remembers of structures and buffers destroyed, judged
// between a recording and its submission; and the structure descriptors vkGetDescriptorEXT made, turned back into
// addresses (pure logic, no driver).
#include <catch2/catch_test_macros.hpp>
#include <cstring>
#include <vector>

#include "object_lifetimes.h"
#include "ray_bindings.h"

namespace asval {
namespace {

VkAccelerationStructureKHR Handle(uint64_t value) { return reinterpret_cast<VkAccelerationStructureKHR>(value); }
VkBuffer BufferHandle(uint64_t value) { return reinterpret_cast<VkBuffer>(value); }

TEST_CASE(
    "lifetime unit: a structure is destroyed since a recording only when it lived then and went before the "
    "submission") {
  ObjectLifetimes destroyed;
  CHECK(destroyed.last_structure_destroyed() == 0);
  destroyed.AddStructure({Handle(0x10), /*created=*/5, /*destroyed=*/20});
  CHECK(destroyed.last_structure_destroyed() == 20);
  ObjectLifetimes::Structure found{};
  // Recorded at 10, submitted at 30: it lived at 10 and went at 20.
  CHECK(destroyed.StructureDestroyedSince(Handle(0x10), {10, 30}, &found) == ObjectLifetimes::Answer::kYes);
  CHECK(found.created == 5);
  // Recorded after it went; recorded before it was created (the handle named another one then, or none).
  CHECK(destroyed.StructureDestroyedSince(Handle(0x10), {25, 30}, &found) == ObjectLifetimes::Answer::kNo);
  CHECK(destroyed.StructureDestroyedSince(Handle(0x10), {3, 30}, &found) == ObjectLifetimes::Answer::kNo);
  // Destroyed after the submission (a batch applied later): not the command buffer's state when it was submitted.
  CHECK(destroyed.StructureDestroyedSince(Handle(0x10), {10, 15}, &found) == ObjectLifetimes::Answer::kNo);
  // Another handle.
  CHECK(destroyed.StructureDestroyedSince(Handle(0x11), {10, 30}, &found) == ObjectLifetimes::Answer::kNo);
}

TEST_CASE(
    "lifetime unit: the newest creation and destruction are maxima, whatever order threads hand their serials in") {
  ObjectLifetimes lifetimes;
  CHECK(lifetimes.last_structure_created() == 0);
  lifetimes.StructureCreated(7);
  lifetimes.StructureCreated(4);  // a thread that took its serial first and got here second
  CHECK(lifetimes.last_structure_created() == 7);
  lifetimes.AddStructure({Handle(0x10), 1, 30});
  lifetimes.AddStructure({Handle(0x11), 2, 25});
  CHECK(lifetimes.last_structure_destroyed() == 30);
  lifetimes.AddBuffer({BufferHandle(0x20), 0x1000, 64, 3, 40});
  lifetimes.AddBuffer({BufferHandle(0x21), 0x2000, 64, 3, 35});
  CHECK(lifetimes.last_buffer_destroyed() == 40);
}

TEST_CASE(
    "lifetime unit: a buffer holds a recorded address when bound before the recording; the oldest destroys "
    "are forgotten, and what they could have answered is unknown") {
  ObjectLifetimes destroyed;
  destroyed.AddBuffer({BufferHandle(0x20), /*address=*/0x1000, /*size=*/256, /*bound=*/4, /*destroyed=*/9});
  ObjectLifetimes::Buffer found{};
  CHECK(destroyed.BufferDestroyedSince(0x10ff, {6, 50}, &found) == ObjectLifetimes::Answer::kYes);
  CHECK(found.handle == BufferHandle(0x20));
  CHECK(destroyed.BufferDestroyedSince(0x1100, {6, 50}, &found) == ObjectLifetimes::Answer::kNo);  // past its end
  CHECK(destroyed.BufferDestroyedSince(0x1000, {3, 50}, &found) == ObjectLifetimes::Answer::kNo);  // bound later
  // Fill the ring past its capacity with other buffers destroyed later: the first one is dropped.
  for (uint64_t i = 0; i < ObjectLifetimes::kCapacity; ++i) {
    destroyed.AddBuffer({BufferHandle(0x100 + i), 0x100000 + i * 0x1000, 256, 10 + i, 11 + i});
  }
  CHECK(destroyed.BufferDestroyedSince(0x1000, {6, 5000}, &found) == ObjectLifetimes::Answer::kUnknown);
  // A recording made after every dropped destroy loses nothing.
  CHECK(destroyed.BufferDestroyedSince(0x1000, {9, 5000}, &found) == ObjectLifetimes::Answer::kNo);
}

TEST_CASE(
    "traces unit: structure descriptors turn back into the addresses they were made from; the oldest are "
    "forgotten past the limit") {
  RayBindings bindings;
  std::vector<unsigned char> bytes(32, 0);
  VkDeviceAddress address = 0;
  CHECK(bindings.structure_descriptor_size() == 0);
  CHECK_FALSE(bindings.StructureOfDescriptor(bytes.data(), bytes.size(), &address));
  bytes[0] = 1;
  bindings.AddStructureDescriptor(bytes.data(), bytes.size(), 0xabc000);
  CHECK(bindings.structure_descriptor_size() == 32);
  REQUIRE(bindings.StructureOfDescriptor(bytes.data(), bytes.size(), &address));
  CHECK(address == 0xabc000);
  bytes[31] = 7;  // one byte differs: not a descriptor the layer saw made
  CHECK_FALSE(bindings.StructureOfDescriptor(bytes.data(), bytes.size(), &address));
  bytes[31] = 0;
  for (uint32_t i = 1; i <= RayBindings::kMaxDescriptors; ++i) {
    std::vector<unsigned char> other(32, 0);
    std::memcpy(other.data() + 4, &i, sizeof(i));
    bindings.AddStructureDescriptor(other.data(), other.size(), 0x100000 + i);
  }
  CHECK_FALSE(bindings.StructureOfDescriptor(bytes.data(), bytes.size(), &address));  // the oldest went
  std::vector<unsigned char> newest(32, 0);
  const uint32_t last = RayBindings::kMaxDescriptors;
  std::memcpy(newest.data() + 4, &last, sizeof(last));
  REQUIRE(bindings.StructureOfDescriptor(newest.data(), newest.size(), &address));
  CHECK(address == 0x100000 + last);
}

}  // namespace
}  // namespace asval
