#pragma once
// Where an acceleration structure's bytes live: its record and the record of the buffer it was created on.
// Shared by the aliasing rules (memory spans) and the host rules (memory properties).
#include <vulkan/vulkan.h>

#include <memory>
#include <optional>

#include "device_state.h"

namespace asval {

struct StructureMemory {
  std::shared_ptr<const AccelerationStructureState> structure;
  std::shared_ptr<const BufferState> buffer;

  bool bound() const { return buffer && buffer->bound && buffer->memory != VK_NULL_HANDLE; }
  // First byte of the structure in its VkDeviceMemory (only when bound()).
  VkDeviceSize memory_offset() const { return buffer->memory_offset + structure->offset; }
};

// nullopt when the structure or its buffer is not known to the layer.
inline std::optional<StructureMemory> MemoryOfStructure(const DeviceState& state, VkAccelerationStructureKHR handle) {
  if (handle == VK_NULL_HANDLE) return std::nullopt;
  std::optional<std::shared_ptr<const AccelerationStructureState>> structure = state.acceleration_structures.find(handle);
  if (!structure || !*structure) return std::nullopt;
  std::optional<std::shared_ptr<const BufferState>> buffer = state.buffers.find((*structure)->buffer);
  if (!buffer || !*buffer) return std::nullopt;
  return StructureMemory{std::move(*structure), std::move(*buffer)};
}

}  // namespace asval
