// The test driver's added memory type (memory_types.h), on hand-written driver properties.
#include "memory_types.h"

#include <catch2/catch_test_macros.hpp>

namespace asval_test_driver {
namespace {

constexpr VkMemoryPropertyFlags kLavapipeFlags =
    VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
    VK_MEMORY_PROPERTY_HOST_CACHED_BIT;

VkPhysicalDeviceMemoryProperties Lavapipe() {
  VkPhysicalDeviceMemoryProperties p{};
  p.memoryTypeCount = 1;
  p.memoryTypes[0] = {kLavapipeFlags, 0};
  p.memoryHeapCount = 1;
  p.memoryHeaps[0] = {1u << 30, VK_MEMORY_HEAP_DEVICE_LOCAL_BIT};
  return p;
}

TEST_CASE("memory types: lavapipe's one type gets a device-local, not host-visible type 1 on its heap") {
  const VkPhysicalDeviceMemoryProperties below = Lavapipe();
  VkPhysicalDeviceMemoryProperties above = below;
  AddMemoryType(&above);
  REQUIRE(above.memoryTypeCount == 2);
  CHECK(above.memoryTypes[0].propertyFlags == kLavapipeFlags);
  CHECK(above.memoryTypes[1].propertyFlags == VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  CHECK(above.memoryTypes[1].heapIndex == 0);
  CHECK(above.memoryHeapCount == 1);
  CHECK(MemoryTypeBelow(below, 1) == 0);
  CHECK(MemoryTypeBelow(below, 0) == 0);
  CHECK(MemoryTypeBitsAbove(below, 0b1) == 0b11);
  CHECK(MemoryTypeBitsAbove(below, 0b0) == 0b0);
}

TEST_CASE("memory types: backed by the first device-local type; nothing added to a full table") {
  VkPhysicalDeviceMemoryProperties below{};
  below.memoryTypeCount = 2;
  below.memoryTypes[0] = {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, 1};
  below.memoryTypes[1] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, 0};
  below.memoryHeapCount = 2;
  VkPhysicalDeviceMemoryProperties above = below;
  AddMemoryType(&above);
  REQUIRE(above.memoryTypeCount == 3);
  CHECK(above.memoryTypes[2].heapIndex == 0);
  CHECK(MemoryTypeBelow(below, 2) == 1);
  CHECK(MemoryTypeBitsAbove(below, 0b01) == 0b001);  // the backing type is not allowed: neither is the added one
  CHECK(MemoryTypeBitsAbove(below, 0b10) == 0b110);

  VkPhysicalDeviceMemoryProperties full = Lavapipe();
  full.memoryTypeCount = VK_MAX_MEMORY_TYPES;
  VkPhysicalDeviceMemoryProperties unchanged = full;
  AddMemoryType(&unchanged);
  CHECK(unchanged.memoryTypeCount == VK_MAX_MEMORY_TYPES);
  CHECK(MemoryTypeBitsAbove(full, 0b1) == 0b1);
}

}  // namespace
}  // namespace asval_test_driver
