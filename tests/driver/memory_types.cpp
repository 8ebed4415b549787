#include "memory_types.h"

namespace asval_test_driver {
namespace {

// The type the added one is made of: below's first device-local type (lavapipe: its only one).
uint32_t BackingType(const VkPhysicalDeviceMemoryProperties& below) {
  for (uint32_t i = 0; i < below.memoryTypeCount; ++i) {
    if (below.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) return i;
  }
  return 0;
}

}  // namespace

uint32_t AddedMemoryType(const VkPhysicalDeviceMemoryProperties& below) {
  if (below.memoryTypeCount == 0 || below.memoryTypeCount >= VK_MAX_MEMORY_TYPES) return UINT32_MAX;
  return below.memoryTypeCount;
}

void AddMemoryType(VkPhysicalDeviceMemoryProperties* properties) {
  const uint32_t added = AddedMemoryType(*properties);
  if (added == UINT32_MAX) return;
  const uint32_t heap = properties->memoryTypes[BackingType(*properties)].heapIndex;
  properties->memoryTypes[added] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, heap};
  properties->memoryTypeCount = added + 1;
}

uint32_t MemoryTypeBelow(const VkPhysicalDeviceMemoryProperties& below, uint32_t type) {
  return type == AddedMemoryType(below) ? BackingType(below) : type;
}

uint32_t MemoryTypeBitsAbove(const VkPhysicalDeviceMemoryProperties& below, uint32_t bits) {
  const uint32_t added = AddedMemoryType(below);
  if (added == UINT32_MAX || !(bits & (1u << BackingType(below)))) return bits;
  return bits | (1u << added);
}

}  // namespace asval_test_driver
