#include "memory_range.h"

#include <algorithm>
#include <functional>

namespace asval {
namespace {

bool IsEmpty(const MemorySpan& span) { return span.memory == VK_NULL_HANDLE || span.begin >= span.end; }

}  // namespace

std::optional<MemorySpan> ResolveMemorySpan(const MemoryBinding& binding, VkDeviceSize offset_in_buffer,
                                            VkDeviceSize size) {
  constexpr VkDeviceSize kMax = ~VkDeviceSize{0};
  if (!binding.bound || binding.memory == VK_NULL_HANDLE) return std::nullopt;
  if (offset_in_buffer > kMax - binding.offset) return std::nullopt;
  const VkDeviceSize begin = binding.offset + offset_in_buffer;
  if (size > kMax - begin) return std::nullopt;
  return MemorySpan{binding.memory, begin, begin + size};
}

bool Overlaps(const MemorySpan& a, const MemorySpan& b) {
  if (IsEmpty(a) || IsEmpty(b) || a.memory != b.memory) return false;
  return a.begin < b.end && b.begin < a.end;
}

std::optional<OverlapPair> FindOverlappingPair(const MemorySpan* spans, std::size_t count,
                                               std::vector<std::size_t>& order) {
  order.clear();
  for (std::size_t i = 0; i < count; ++i) {
    if (!IsEmpty(spans[i])) order.push_back(i);
  }
  // Ties on (memory, begin) are broken by index so that the reported pair does not depend on the sort.
  std::sort(order.begin(), order.end(), [spans](std::size_t a, std::size_t b) {
    const MemorySpan& x = spans[a];
    const MemorySpan& y = spans[b];
    if (x.memory != y.memory) return std::less<VkDeviceMemory>{}(x.memory, y.memory);
    if (x.begin != y.begin) return x.begin < y.begin;
    return a < b;
  });

  // Within one memory, every earlier span begins at or before the current one, so the current span overlaps
  // an earlier one iff it begins before the furthest end reached so far.
  std::size_t reach_index = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    const MemorySpan& span = spans[i];
    const bool same_memory = k > 0 && spans[reach_index].memory == span.memory;
    if (same_memory && span.begin < spans[reach_index].end) {
      return OverlapPair{std::min(reach_index, i), std::max(reach_index, i)};
    }
    if (!same_memory || span.end > spans[reach_index].end) reach_index = i;
  }
  return std::nullopt;
}

std::optional<OverlapPair> FindOverlappingPair(const std::vector<MemorySpan>& spans) {
  std::vector<std::size_t> order;
  return FindOverlappingPair(spans.data(), spans.size(), order);
}

}  // namespace asval
