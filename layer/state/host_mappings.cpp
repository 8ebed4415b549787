#include "host_mappings.h"

#include <iterator>
#include <mutex>

namespace asval {

void HostMappings::Map(VkDeviceMemory memory, VkDeviceSize offset, VkDeviceSize size, const void* pointer) {
  const auto begin = reinterpret_cast<uintptr_t>(pointer);
  if (!pointer || size == 0 || size > UINTPTR_MAX - begin) return;
  const uintptr_t end = begin + static_cast<uintptr_t>(size);
  std::unique_lock lock(mutex_);
  EraseLocked(memory);
  // Records that overlap [begin, end) belong to memory freed or unmapped behind the layer's back.
  auto it = by_begin_.lower_bound(begin);
  if (it != by_begin_.begin() && std::prev(it)->second.end > begin) --it;
  while (it != by_begin_.end() && it->first < end) {
    by_memory_.erase(it->second.memory);
    it = by_begin_.erase(it);
  }
  by_begin_.emplace(begin, HostMapping{begin, end, memory, offset});
  by_memory_[memory] = begin;
}

void HostMappings::Unmap(VkDeviceMemory memory) {
  std::unique_lock lock(mutex_);
  EraseLocked(memory);
}

void HostMappings::EraseLocked(VkDeviceMemory memory) {
  const auto found = by_memory_.find(memory);
  if (found == by_memory_.end()) return;
  by_begin_.erase(found->second);
  by_memory_.erase(found);
}

const HostMapping* HostMappings::ContainingLocked(uintptr_t address) const {
  auto it = by_begin_.upper_bound(address);
  if (it == by_begin_.begin()) return nullptr;
  --it;
  return address < it->second.end ? &it->second : nullptr;
}

std::optional<HostMapping> HostMappings::Containing(uintptr_t address) const {
  std::shared_lock lock(mutex_);
  const HostMapping* mapping = ContainingLocked(address);
  if (!mapping) return std::nullopt;
  return *mapping;
}

std::optional<HostMapping> HostMappings::OfMemory(VkDeviceMemory memory) const {
  std::shared_lock lock(mutex_);
  const auto begin = by_memory_.find(memory);
  if (begin == by_memory_.end()) return std::nullopt;
  const auto mapping = by_begin_.find(begin->second);
  if (mapping == by_begin_.end()) return std::nullopt;
  return mapping->second;
}

uintptr_t HostMappings::ContiguousEnd(uintptr_t address) const {
  std::shared_lock lock(mutex_);
  const HostMapping* mapping = ContainingLocked(address);
  if (!mapping) return 0;
  uintptr_t end = mapping->end;
  for (auto it = by_begin_.find(end); it != by_begin_.end() && it->first == end; it = by_begin_.find(end)) {
    end = it->second.end;
  }
  return end;
}

std::size_t HostMappings::size() const {
  std::shared_lock lock(mutex_);
  return by_begin_.size();
}

}  // namespace asval
