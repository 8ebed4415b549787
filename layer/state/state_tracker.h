#pragma once
// Updates the shadow state after the driver accepted a call. The loader hooks call these after a successful
// downcall; they take only the locks of the maps they touch and never call the driver except through the
// dispatch functions passed in (for the device addresses the layer queries itself).
#include <vulkan/vulkan.h>

#include "device_state.h"

namespace asval {

struct DeviceDispatchTable;

void RecordAllocateMemory(DeviceState& state, const VkMemoryAllocateInfo& info, VkDeviceMemory memory);
void RecordFreeMemory(DeviceState& state, VkDeviceMemory memory);

void RecordCreateBuffer(DeviceState& state, const VkBufferCreateInfo& info, VkBuffer buffer);
void RecordDestroyBuffer(DeviceState& state, VkBuffer buffer);
// Publishes the binding and, for SHADER_DEVICE_ADDRESS buffers, queries and maps the device address.
void RecordBindBufferMemory(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device, VkBuffer buffer,
                            VkDeviceMemory memory, VkDeviceSize offset);

void RecordCreateAccelerationStructure(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device,
                                       const VkAccelerationStructureCreateInfoKHR& info,
                                       VkAccelerationStructureKHR handle);
void RecordDestroyAccelerationStructure(DeviceState& state, VkAccelerationStructureKHR handle);

// Reads the enabled features from a VkDeviceCreateInfo pNext chain.
DeviceFeatures ParseEnabledFeatures(const VkDeviceCreateInfo& info);

}  // namespace asval
