// Buffer bytes -> VkDeviceMemory bytes, and overlap tests between such spans.
//
// Aliasing rules (e.g. "scratch of one build must not overlap the scratch, source or destination of another
// info in the same command") are about memory, not buffers: two different buffers bound to the same
// VkDeviceMemory can alias. These helpers map buffer sub-ranges onto their memory and find overlaps.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <optional>
#include <vector>

namespace asval {

// Where a non-sparse buffer's bytes live (from vkBindBufferMemory / vkBindBufferMemory2).
struct MemoryBinding {
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;  // memoryOffset of the bind
  bool bound = false;
};

// Half-open byte range [begin, end) of one VkDeviceMemory.
struct MemorySpan {
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize begin = 0;
  VkDeviceSize end = 0;
};

// The memory bytes behind [offset_in_buffer, offset_in_buffer + size) of a buffer. nullopt when the buffer is
// not bound or the arithmetic would pass 2^64 - 1 (no real allocation is that large). Checking the range
// against the buffer's size is the caller's job: that is its own VUID.
std::optional<MemorySpan> ResolveMemorySpan(const MemoryBinding& binding, VkDeviceSize offset_in_buffer,
                                            VkDeviceSize size);

// Same, non-null memory and intersecting ranges. An empty span overlaps nothing; neither does a span of
// VK_NULL_HANDLE memory (it describes no bytes).
bool Overlaps(const MemorySpan& a, const MemorySpan& b);

// Two indices into the input, first < second, whose spans overlap.
struct OverlapPair {
  std::size_t first = 0;
  std::size_t second = 0;
};

// Finds an overlapping pair among `count` spans in O(N log N): sort by (memory, begin), then sweep keeping the
// span that reaches furthest so far in the current memory. Returns the first pair met in that sweep (so the
// answer is deterministic), or nullopt if no two spans overlap. `order` is caller-owned scratch space, reused
// to avoid an allocation per call (a build command may carry thousands of infos).
std::optional<OverlapPair> FindOverlappingPair(const MemorySpan* spans, std::size_t count,
                                               std::vector<std::size_t>& order);
std::optional<OverlapPair> FindOverlappingPair(const std::vector<MemorySpan>& spans);

}  // namespace asval
