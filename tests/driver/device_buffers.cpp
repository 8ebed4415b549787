#include "device_buffers.h"

namespace asval_test_driver {

void DeviceBuffers::Created(VkBuffer buffer, const VkBufferCreateInfo& info) {
  std::lock_guard<std::mutex> lock(lock_);
  buffers_[buffer] = Buffer{info.size, (info.usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0, 0};
}

bool DeviceBuffers::HasAddress(VkBuffer buffer) const {
  std::lock_guard<std::mutex> lock(lock_);
  const auto it = buffers_.find(buffer);
  return it != buffers_.end() && it->second.addressable;
}

void DeviceBuffers::Bound(VkBuffer buffer, VkDeviceAddress address) {
  std::lock_guard<std::mutex> lock(lock_);
  const auto it = buffers_.find(buffer);
  if (it == buffers_.end()) return;
  it->second.address = address;
  by_address_.emplace(address, buffer);
}

void DeviceBuffers::Destroyed(VkBuffer buffer) {
  std::lock_guard<std::mutex> lock(lock_);
  const auto it = buffers_.find(buffer);
  if (it == buffers_.end()) return;
  const auto range = by_address_.equal_range(it->second.address);
  for (auto entry = range.first; entry != range.second; ++entry) {
    if (entry->second == buffer) {
      by_address_.erase(entry);
      break;
    }
  }
  buffers_.erase(it);
}

bool DeviceBuffers::Find(VkDeviceAddress address, VkDeviceSize bytes, VkBuffer* buffer, VkDeviceSize* offset) const {
  std::lock_guard<std::mutex> lock(lock_);
  // Any buffer starting at or below the address that holds the whole range (buffers may alias one memory).
  for (auto it = by_address_.upper_bound(address); it != by_address_.begin();) {
    --it;
    const Buffer& b = buffers_.at(it->second);
    if (address + bytes <= it->first + b.size) {
      *buffer = it->second;
      *offset = address - it->first;
      return true;
    }
  }
  return false;
}

}  // namespace asval_test_driver
