#pragma once
// The app's buffer a capture reads a range from: bound and holding the whole range; for a copy also created
// copyable by the layer (BufferState::capture_source: TRANSFER_SRC added at vkCreateBuffer), while the layer's
// reducing dispatch reads through the device address that SHADER_DEVICE_ADDRESS usage gave.
#include <vulkan/vulkan.h>

#include <memory>
#include <optional>

#include "device_state.h"

namespace asval {

enum class CaptureRead { kCopy, kInPlace };

inline std::optional<AddressHit> CaptureSourceBuffer(const DeviceState& state, VkDeviceAddress address,
                                                     VkDeviceSize size, CaptureRead read) {
  return state.buffer_addresses.FindCovering(address, size, [&](VkBuffer buffer) {
    std::optional<std::shared_ptr<const BufferState>> b = state.buffers.find(buffer);
    return b && *b && (*b)->bound && (read == CaptureRead::kInPlace || (*b)->capture_source);
  });
}

}  // namespace asval
