#pragma once
// Updates the shadow state of objects: memory, buffers, structures, mappings, query pools. The loader hooks
// call these after a successful downcall (destruction: before the downcall, because afterwards another
// thread may be handed the same handle value); they take only the locks of the maps they touch and never call
// the driver except through the dispatch functions passed in (for the device addresses the layer queries
// itself). Command buffers: command_buffers.h; the build history: history_recorder.h.
#include <vulkan/vulkan.h>

#include "device_state.h"

namespace asval {

struct DeviceDispatchTable;

void RecordAllocateMemory(DeviceState& state, const VkMemoryAllocateInfo& info, VkDeviceMemory memory);
void RecordFreeMemory(DeviceState& state, VkDeviceMemory memory);

// info: as the app gave it. copyable: the buffer was created with TRANSFER_SRC (the app's, or the layer's for
// build inputs): the capture may copy from it.
void RecordCreateBuffer(DeviceState& state, const VkBufferCreateInfo& info, VkBuffer buffer, bool copyable = false);
void RecordDestroyBuffer(DeviceState& state, VkBuffer buffer);
// Publishes the binding and, for SHADER_DEVICE_ADDRESS buffers, queries and maps the device address.
void RecordBindBufferMemory(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device, VkBuffer buffer,
                            VkDeviceMemory memory, VkDeviceSize offset);

void RecordCreateAccelerationStructure(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device,
                                       const VkAccelerationStructureCreateInfoKHR& info,
                                       VkAccelerationStructureKHR handle);
// Also ends the structure's history: a new structure with this handle value starts fresh.
void RecordDestroyAccelerationStructure(DeviceState& state, VkAccelerationStructureKHR handle);

// vkMapMemory (after success) / vkUnmapMemory: where the app's host pointers into memory are.
void RecordMapMemory(DeviceState& state, VkDeviceMemory memory, VkDeviceSize offset, VkDeviceSize size,
                     void* host_address);
void RecordUnmapMemory(DeviceState& state, VkDeviceMemory memory);

// Query pools: their type and size (queryPool-02493, query-04880) and, for serialization-size pools, the
// slots the history attaches to structures.
void RecordCreateQueryPool(DeviceState& state, const VkQueryPoolCreateInfo& info, VkQueryPool pool);
void RecordDestroyQueryPool(DeviceState& state, VkQueryPool pool);

// Reads the enabled features from a VkDeviceCreateInfo pNext chain.
DeviceFeatures ParseEnabledFeatures(const VkDeviceCreateInfo& info);

}  // namespace asval
