#pragma once
// Where an acceleration structure's bytes live: its record and the record of the buffer it was created on. The
// one resolver of structure -> buffer -> memory: every rule family and the history use it.
//
// A structure holds its buffer's identity (BufferState::id), not only the handle: after vkDestroyBuffer the
// handle value may be handed to a new buffer, which must never be taken for the structure's.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <memory>
#include <optional>

#include "device_state.h"
#include "memory_range.h"

namespace asval {

struct StructureMemory {
  std::shared_ptr<const AccelerationStructureState> structure;
  std::shared_ptr<const BufferState> buffer;

  bool bound() const { return buffer && buffer->bound && buffer->memory != VK_NULL_HANDLE; }
  // First byte of the structure in its VkDeviceMemory (only when bound()).
  VkDeviceSize memory_offset() const { return buffer->memory_offset + structure->offset; }
  // The VkDeviceMemory bytes the structure occupies, or its first `accessed` bytes (what a build writes); nullopt
  // when not bound (or the arithmetic overflows).
  std::optional<MemorySpan> Span(VkDeviceSize accessed = ~VkDeviceSize{0}) const {
    if (!bound()) return std::nullopt;
    return ResolveMemorySpan(MemoryBinding{buffer->memory, buffer->memory_offset, true}, structure->offset,
                             std::min(structure->size, accessed));
  }
};

// The live buffer a structure was created on; null when it is unknown or was destroyed (even if another buffer
// now has its handle value).
inline std::shared_ptr<const BufferState> BufferOfStructure(const DeviceState& state,
                                                            const AccelerationStructureState& structure) {
  std::optional<std::shared_ptr<const BufferState>> buffer = state.buffers.find(structure.buffer);
  if (!buffer || !*buffer || (*buffer)->id != structure.buffer_id) return nullptr;
  return std::move(*buffer);
}

// Whether a structure's storage is bound now (pInfos-03709; the snapshot of live structures keeps it).
inline StructureStorage StorageOfStructure(const DeviceState& state, const AccelerationStructureState& structure) {
  if (structure.buffer_id == 0) return StructureStorage::kUnknown;  // created on a buffer the layer never saw
  std::shared_ptr<const BufferState> buffer = BufferOfStructure(state, structure);
  if (!buffer) return StructureStorage::kBufferDestroyed;
  // Sparse buffers are bound by vkQueueBindSparse, which the layer does not follow.
  if (buffer->create_flags & VK_BUFFER_CREATE_SPARSE_BINDING_BIT) return StructureStorage::kUnknown;
  const bool freed = buffer->memory_freed;
  if (StructureMemory{nullptr, std::move(buffer)}.bound()) return StructureStorage::kBound;
  return freed ? StructureStorage::kMemoryFreed : StructureStorage::kUnbound;
}

// nullopt when the structure or its buffer is not known to the layer.
inline std::optional<StructureMemory> MemoryOfStructure(const DeviceState& state, VkAccelerationStructureKHR handle) {
  if (handle == VK_NULL_HANDLE) return std::nullopt;
  std::optional<std::shared_ptr<const AccelerationStructureState>> structure = state.acceleration_structures.find(handle);
  if (!structure || !*structure) return std::nullopt;
  std::shared_ptr<const BufferState> buffer = BufferOfStructure(state, **structure);
  if (!buffer) return std::nullopt;
  return StructureMemory{std::move(*structure), std::move(buffer)};
}

}  // namespace asval
