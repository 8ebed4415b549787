#pragma once
// Where a capture reads a range of device addresses from. The reducing dispatch reads through the device address
// itself (the app's buffer holding the range, bound, is only looked up to know that the addresses are backed). A
// copy reads through a buffer whose lifetime the layer controls (memory_aliases.h): its own buffer over the memory
// that the app's buffer holding the range is bound to, at the same bytes; or, in a dedicated allocation, the
// app's buffer itself, when the layer made it copyable (BufferState::capture_source).
#include <vulkan/vulkan.h>

#include <algorithm>
#include <memory>
#include <optional>

#include "device_state.h"
#include "memory_aliases.h"

namespace asval {

// A live buffer of the app's, bound to memory, whose device-address range covers [address, address + size).
inline std::optional<AddressHit> BoundBufferCovering(const DeviceState& state, VkDeviceAddress address,
                                                     VkDeviceSize size,
                                                     std::shared_ptr<const BufferState>* found = nullptr) {
  return state.buffer_addresses.FindCovering(address, size, [&](VkBuffer buffer) {
    std::optional<std::shared_ptr<const BufferState>> b = state.buffers.find(buffer);
    if (!b || !*b || !(*b)->bound || (*b)->memory == VK_NULL_HANDLE) return false;
    if (found) *found = std::move(*b);
    return true;
  });
}

// What a vkCmdCopyBuffer of the layer's names: its source buffer, the offset of the first byte in it, and how many
// bytes from there the buffer of the app's holding the address has (at most what the source covers).
struct CopySource {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory aliased = VK_NULL_HANDLE;  // the memory `buffer` is the layer's alias of; null: the app's buffer
  VkDeviceSize offset = 0;
  VkDeviceSize bytes_left = 0;
};

// The copy source of `address` (at least `size` bytes from it), which lies in the app's buffer `b` whose range
// starts at `base`; nullopt when the layer has nothing it may name there (counted by the caller).
inline std::optional<CopySource> CopySourceIn(const DeviceState& state, MemoryAliases& aliases, const BufferState& b,
                                              VkDeviceAddress base, VkDeviceSize range_size, VkDeviceAddress address,
                                              VkDeviceSize size) {
  if (address < base || address - base > range_size) return std::nullopt;
  const VkDeviceSize in_buffer = address - base;
  const VkDeviceSize in_buffer_left = range_size - in_buffer;
  if (size > in_buffer_left) return std::nullopt;
  const std::shared_ptr<const MemoryAlias> alias = aliases.Of(state, b.memory);
  if (!alias) return std::nullopt;
  if (alias->dedicated_to != VK_NULL_HANDLE) {
    // Only that buffer can be bound there; it is the only buffer whose addresses lie in it.
    if (alias->dedicated_to != b.handle || !b.capture_source) return std::nullopt;
    return CopySource{b.handle, VK_NULL_HANDLE, in_buffer, in_buffer_left};
  }
  if (alias->buffer == VK_NULL_HANDLE || b.memory_offset > alias->size) return std::nullopt;
  const VkDeviceSize alias_left = alias->size - b.memory_offset;
  if (in_buffer > alias_left || size > alias_left - in_buffer) return std::nullopt;
  return CopySource{alias->buffer, b.memory, b.memory_offset + in_buffer,
                    std::min(in_buffer_left, alias_left - in_buffer)};
}

// The copy source of [address, address + size); nullopt with *why: no bound buffer of the app's covers the range
// (kUnknownAddress), or one does but the layer has nothing it may name there (kBufferNotCopyable).
inline std::optional<CopySource> CaptureCopySource(const DeviceState& state, MemoryAliases& aliases,
                                                   VkDeviceAddress address, VkDeviceSize size, CaptureSkip* why) {
  std::shared_ptr<const BufferState> b;
  const std::optional<AddressHit> hit = BoundBufferCovering(state, address, size, &b);
  if (!hit || !b) {
    *why = CaptureSkip::kUnknownAddress;
    return std::nullopt;
  }
  std::optional<CopySource> source = CopySourceIn(state, aliases, *b, hit->base, hit->size, address, size);
  if (!source) *why = CaptureSkip::kBufferNotCopyable;
  return source;
}

}  // namespace asval
