#pragma once
// VK_NV_ray_tracing structures in the shadow state: created with their build parameters, bound to memory by
// vkBindAccelerationStructureMemoryNV, destroyed. Their build, copy and property-query operations join the KHR
// structures' history (history_recorder.h), keyed by the handle's value: NvHistoryKey.
#include <vulkan/vulkan.h>

#include <memory>
#include <optional>

#include "device_state.h"
#include "memory_range.h"

namespace asval {

struct DeviceDispatchTable;

// The key an NV structure's operations and history use: its handle's value.
inline VkAccelerationStructureKHR NvHistoryKey(VkAccelerationStructureNV handle) {
  return reinterpret_cast<VkAccelerationStructureKHR>(handle);
}
inline VkAccelerationStructureNV NvHandleOf(VkAccelerationStructureKHR key) {
  return reinterpret_cast<VkAccelerationStructureNV>(key);
}

// After a successful vkCreateAccelerationStructureNV: its parameters, and the three memory requirements, asked of
// the driver now (once per structure; a cold path) where the device has the command.
void RecordCreateAccelerationStructureNV(DeviceState& state, const DeviceDispatchTable& dispatch, VkDevice device,
                                         const VkAccelerationStructureCreateInfoNV& info,
                                         VkAccelerationStructureNV handle);
// After a successful vkBindAccelerationStructureMemoryNV, one bind info.
void RecordBindAccelerationStructureMemoryNV(DeviceState& state, const VkBindAccelerationStructureMemoryInfoNV& bind);
// Before the downcall of vkDestroyAccelerationStructureNV: the record and its history end.
void RecordDestroyAccelerationStructureNV(DeviceState& state, VkAccelerationStructureNV handle);
// A KHR structure was created under a handle value a live NV structure has: that one leaves the history.
void NoteKhrStructureKey(DeviceState& state, VkAccelerationStructureKHR handle);

// The live NV structure whose operations a history key names (not one sharing its key with a KHR structure).
std::shared_ptr<const NvStructureState> FindNvByKey(const DeviceState& state, VkAccelerationStructureKHR key);

// The memory bytes the structure occupies: its binding and vkGetAccelerationStructureMemoryRequirementsNV's object
// size. nullopt when not bound or the size is unknown.
std::optional<MemorySpan> NvStructureSpan(const NvStructureState& structure);

}  // namespace asval
