#pragma once
// The buffers one build command has already looked up. A recorded build reads many ranges of the same few
// buffers: one vertex buffer for many geometries, one scratch buffer sliced per info, one storage buffer
// holding many structures. The memo keeps the last few buffers found (their address range, usage and memory
// binding), so each is looked up in the shared maps (locks, hashing) once per call rather than once per
// range. It lives on the stack of one call: nothing in it outlives the command, so it cannot go stale.
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>

#include "device_state.h"

namespace asval {

struct KnownBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceAddress base = 0;  // device address range [base, base + size); size 0: the buffer has none
  VkDeviceSize size = 0;
  VkBufferUsageFlags usage = 0;
  bool bound = false;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize memory_offset = 0;

  bool Holds(VkDeviceAddress address, VkDeviceSize bytes) const {
    return size != 0 && address >= base && address - base <= size && bytes <= size - (address - base);
  }
};

class BufferMemo {
 public:
  // A bound buffer whose address range holds all of [address, address + bytes) (bytes 0: just `address`) and
  // that was created with every bit of `usage`; false when none does.
  bool Holding(const DeviceState& state, VkDeviceAddress address, VkDeviceSize bytes, VkBufferUsageFlags usage,
               KnownBuffer* out);
  // The record of `buffer`; false when the layer does not know the buffer.
  bool Find(const DeviceState& state, VkBuffer buffer, KnownBuffer* out);

 private:
  static constexpr int kEntries = 8;
  void Remember(const KnownBuffer& entry);

  std::array<KnownBuffer, kEntries> entries_{};
  int count_ = 0;
  int next_ = 0;  // round-robin replacement once full
};

}  // namespace asval
