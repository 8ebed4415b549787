#pragma once
// The structures a binding read from a descriptor buffer names (VK_EXT_descriptor_buffer): the descriptors' bytes
// now, from the app's host mapping of the memory under the buffer (a valid app wrote them before submitting and does
// not rewrite them while pending work reads them), turned back into the structure address vkGetDescriptorEXT made
// them from (RayBindings::StructureOfDescriptor), and that address into the live structure there. Shared by the
// traces check at submission, the lifetime checks at a destroy and the in-flight bookkeeping (traced_tops.h).
#include <cstddef>
#include <cstdint>
#include <memory>

#include "buffer_holders.h"
#include "device_state.h"
#include "structure_memory.h"

namespace asval {

enum class BufferDescriptor : uint8_t {
  kUnreadable,        // not in memory the app mapped, or no structure descriptor was made through the layer
  kUnknownStructure,  // bytes no vkGetDescriptorEXT made, or an address of no live structure (or of several)
  kNull,              // a null descriptor: nothing is read
  kStructure,         // the live structure there
};

// Calls f(BufferDescriptor, const AccelerationStructureState* structure) for each of the binding's descriptors
// (once with kUnreadable when no structure descriptor size is known). `structure` is set for kStructure only.
template <typename F>
void ForEachBufferDescriptor(const DeviceState& state, VkDeviceAddress first, uint32_t count, F&& f) {
  const std::size_t size = state.ray_bindings.structure_descriptor_size();
  if (size == 0) return f(BufferDescriptor::kUnreadable, nullptr);
  std::shared_ptr<const LiveStructureAddresses> live;
  for (uint32_t i = 0; i < count; ++i) {
    const unsigned char* bytes = MappedBytesAt(state, first + VkDeviceSize{i} * size, size);
    if (!bytes) {
      f(BufferDescriptor::kUnreadable, nullptr);
      continue;
    }
    VkDeviceAddress address = 0;
    if (!state.ray_bindings.StructureOfDescriptor(bytes, size, &address)) {
      f(BufferDescriptor::kUnknownStructure, nullptr);
      continue;
    }
    if (address == 0) {
      f(BufferDescriptor::kNull, nullptr);
      continue;
    }
    if (!live) {
      live = state.live_structure_addresses.Get(
          state.acceleration_structures, state.structure_storage_changes.Read(),
          [&](const AccelerationStructureState& s) { return StorageOfStructure(state, s); },
          state.failures().structures_incomplete.load(std::memory_order_relaxed));
    }
    const std::ptrdiff_t k = live->Find(address);
    // No live structure there (destroyed since the descriptor was made), or several: which one is not known.
    if (k < 0 || live->shared[static_cast<std::size_t>(k)]) {
      f(BufferDescriptor::kUnknownStructure, nullptr);
      continue;
    }
    f(BufferDescriptor::kStructure, live->structures[static_cast<std::size_t>(k)].get());
  }
}

}  // namespace asval
