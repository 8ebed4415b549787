// The state tracker without a driver: what a create/bind/destroy sequence leaves in the shadow maps, with a
// fake dispatch table standing in for the driver's address queries.
#include <catch2/catch_test_macros.hpp>

#include "memory_range.h"
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
VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeAsAddress(VkDevice, const VkAccelerationStructureDeviceAddressInfoKHR* info) {
  return reinterpret_cast<uintptr_t>(info->accelerationStructure) * 0x100;
}

DeviceDispatchTable FakeDispatch() {
  DeviceDispatchTable d{};
  d.GetBufferDeviceAddress = &FakeBufferAddress;
  d.GetAccelerationStructureDeviceAddressKHR = &FakeAsAddress;
  return d;
}

VkBufferCreateInfo BufferInfo(VkDeviceSize size, VkBufferUsageFlags usage) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  return info;
}

TEST_CASE("buffers: creation, binding with address, aliasing lookup, destruction", "[state]") {
  DeviceState state;
  const DeviceDispatchTable dispatch = FakeDispatch();
  const VkDevice device = Fake<VkDevice>(1);
  const VkDeviceMemory memory = Fake<VkDeviceMemory>(100);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags, 1 << 20, 0};
  RecordAllocateMemory(state, alloc, memory);
  REQUIRE(state.memories.find(memory));
  CHECK((*state.memories.find(memory))->allocate_flags == VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT);

  const VkBuffer a = Fake<VkBuffer>(2), b = Fake<VkBuffer>(3), no_address = Fake<VkBuffer>(4);
  RecordCreateBuffer(state, BufferInfo(4096, VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT), a);
  RecordCreateBuffer(state, BufferInfo(4096, VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT), b);
  RecordCreateBuffer(state, BufferInfo(4096, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT), no_address);
  CHECK_FALSE((*state.buffers.find(a))->bound);

  RecordBindBufferMemory(state, dispatch, device, a, memory, 0);
  RecordBindBufferMemory(state, dispatch, device, b, memory, 1024);  // overlaps a's memory
  RecordBindBufferMemory(state, dispatch, device, no_address, memory, 0);
  const auto ra = *state.buffers.find(a);
  CHECK(ra->bound);
  CHECK(ra->memory == memory);
  CHECK(ra->device_address == 2 * 0x10000);
  CHECK((*state.buffers.find(no_address))->device_address == 0);  // no SHADER_DEVICE_ADDRESS: never queried

  auto covering = state.buffer_addresses.FindCovering(2 * 0x10000 + 100, 200);
  REQUIRE(covering);
  CHECK(covering->buffer == a);
  CHECK_FALSE(state.buffer_addresses.FindCovering(2 * 0x10000 + 4000, 200));  // runs past a's end

  // a and b alias through their memory even though their addresses differ.
  const auto rb = *state.buffers.find(b);
  auto span_a = ResolveMemorySpan(MemoryBinding{ra->memory, ra->memory_offset, ra->bound}, 2000, 100);
  auto span_b = ResolveMemorySpan(MemoryBinding{rb->memory, rb->memory_offset, rb->bound}, 0, 1000);
  REQUIRE(span_a);
  REQUIRE(span_b);
  CHECK(Overlaps(*span_a, *span_b));

  RecordDestroyBuffer(state, a);
  CHECK_FALSE(state.buffers.find(a));
  CHECK_FALSE(state.buffer_addresses.FindCovering(2 * 0x10000 + 100, 200));
  RecordFreeMemory(state, memory);
  CHECK_FALSE(state.memories.find(memory));
}

TEST_CASE("maintenance5 usage flags replace the create info's usage", "[state]") {
  struct Usage2 {
    VkStructureType sType;
    const void* pNext;
    uint64_t usage;
  } usage2{static_cast<VkStructureType>(1000470006), nullptr,
           VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | (uint64_t{1} << 40)};
  DeviceState state;
  VkBufferCreateInfo info = BufferInfo(64, 0);
  info.pNext = &usage2;
  RecordCreateBuffer(state, info, Fake<VkBuffer>(9));
  CHECK((*state.buffers.find(Fake<VkBuffer>(9)))->usage == VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
}

TEST_CASE("acceleration structures: the address is queried only when the app could query it", "[state]") {
  DeviceState state;
  const DeviceDispatchTable dispatch = FakeDispatch();
  const VkDevice device = Fake<VkDevice>(1);
  const VkBuffer with_address = Fake<VkBuffer>(5), without = Fake<VkBuffer>(6);
  RecordCreateBuffer(state, BufferInfo(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR |
                                                    VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT), with_address);
  RecordCreateBuffer(state, BufferInfo(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR), without);
  RecordBindBufferMemory(state, dispatch, device, with_address, Fake<VkDeviceMemory>(50), 0);
  RecordBindBufferMemory(state, dispatch, device, without, Fake<VkDeviceMemory>(50), 1 << 16);

  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = with_address;
  info.offset = 256;
  info.size = 1024;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  RecordCreateAccelerationStructure(state, dispatch, device, info, Fake<VkAccelerationStructureKHR>(7));
  info.buffer = without;
  RecordCreateAccelerationStructure(state, dispatch, device, info, Fake<VkAccelerationStructureKHR>(8));

  const auto as7 = *state.acceleration_structures.find(Fake<VkAccelerationStructureKHR>(7));
  CHECK(as7->device_address == 7 * 0x100);
  CHECK(as7->offset == 256);
  CHECK(as7->size == 1024);
  CHECK(as7->type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  CHECK((*state.acceleration_structures.find(Fake<VkAccelerationStructureKHR>(8)))->device_address == 0);
  RecordDestroyAccelerationStructure(state, Fake<VkAccelerationStructureKHR>(7));
  CHECK_FALSE(state.acceleration_structures.find(Fake<VkAccelerationStructureKHR>(7)));
}

TEST_CASE("enabled features are read from every structure that can carry them", "[state]") {
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  as.accelerationStructure = VK_TRUE;
  as.accelerationStructureHostCommands = VK_TRUE;
  VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &as};
  v12.bufferDeviceAddress = VK_TRUE;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &v12};
  const DeviceFeatures f = ParseEnabledFeatures(info);
  CHECK(f.acceleration_structure);
  CHECK(f.acceleration_structure_host_commands);
  CHECK_FALSE(f.acceleration_structure_indirect_build);
  CHECK(f.buffer_device_address);
  CHECK_FALSE(f.ray_query);
}

}  // namespace
}  // namespace asval
