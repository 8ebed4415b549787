#pragma once
// Host pointers the app got from vkMapMemory, by address: a host build's scratch (and other host pointers)
// that start inside a mapping can be checked against the mapping's end (pInfos-03725/03726), which is the
// only host memory the layer knows the extent of.
//
// Thread safety: every member may be called concurrently; lookups take a shared lock, map/unmap an exclusive
// one (vkMapMemory is rare next to recording).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <optional>
#include <shared_mutex>
#include <unordered_map>

#include "concurrent_map.h"

namespace asval {

struct HostMapping {
  uintptr_t begin = 0;  // [begin, end) of the app's address space
  uintptr_t end = 0;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;  // of begin in the memory
};

class HostMappings {
 public:
  // vkMapMemory returned `pointer` for `size` bytes (already resolved from VK_WHOLE_SIZE) at `offset`.
  // Replaces any earlier mapping of the memory, and any record overlapping the new range (stale: two live
  // mappings never share addresses).
  void Map(VkDeviceMemory memory, VkDeviceSize offset, VkDeviceSize size, const void* pointer);
  // vkUnmapMemory, or vkFreeMemory (which unmaps implicitly).
  void Unmap(VkDeviceMemory memory);

  // The mapping that contains `address`.
  std::optional<HostMapping> Containing(uintptr_t address) const;
  // The mapping of `memory` (nullopt: not mapped).
  std::optional<HostMapping> OfMemory(VkDeviceMemory memory) const;
  // The end of the run of mappings that starts with the one containing `address` and continues through
  // mappings that begin exactly where the previous one ends; 0 when no mapping contains `address`.
  uintptr_t ContiguousEnd(uintptr_t address) const;

  std::size_t size() const;

 private:
  // Under an exclusive lock already held.
  void EraseLocked(VkDeviceMemory memory);
  // Under a lock already held.
  const HostMapping* ContainingLocked(uintptr_t address) const;

  mutable std::shared_mutex mutex_;
  std::map<uintptr_t, HostMapping> by_begin_;
  std::unordered_map<VkDeviceMemory, uintptr_t, HandleHash<VkDeviceMemory>> by_memory_;
};

}  // namespace asval
