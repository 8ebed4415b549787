#pragma once
// One memory type more than the driver below has: device-local and not host-visible, where a discrete GPU keeps
// its acceleration structures. Lavapipe's only type is host-visible, so without it the host commands' rules on
// host-visible memory (vkBuildAccelerationStructuresKHR-pInfos-03722..03724, the host copies' and property
// writes' buffer-03727/03728/03730/03731/03733) could not fire through the loader. Its allocations are made of
// the driver below's first device-local type (so the test driver's host commands still run on them); mapping one
// is the application's error, as on a real driver, and is not refused here.
#include <vulkan/vulkan.h>

#include <cstdint>

namespace asval_test_driver {

// The type the test driver adds to below's properties, or UINT32_MAX when below already has every type it may.
uint32_t AddedMemoryType(const VkPhysicalDeviceMemoryProperties& below);

// below's properties with the added type appended (what the layers above see).
void AddMemoryType(VkPhysicalDeviceMemoryProperties* properties);

// The type below that an allocation of `type` (as the layers above name it) is made of.
uint32_t MemoryTypeBelow(const VkPhysicalDeviceMemoryProperties& below, uint32_t type);

// A resource's memoryTypeBits as the layers above see them: the added type wherever its backing type is allowed.
uint32_t MemoryTypeBitsAbove(const VkPhysicalDeviceMemoryProperties& below, uint32_t bits);

}  // namespace asval_test_driver
