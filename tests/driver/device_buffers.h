#pragma once
// The buffers of a device that have device addresses, so that the test driver can read what an address names
// (an indirect build's range infos) with a copy of the driver below: buffer, offset.
#include <vulkan/vulkan.h>

#include <map>
#include <mutex>
#include <unordered_map>

namespace asval_test_driver {

class DeviceBuffers {
 public:
  void Created(VkBuffer buffer, const VkBufferCreateInfo& info);
  // Bound: its address, when it may have one (SHADER_DEVICE_ADDRESS usage), as the driver below gives it.
  void Bound(VkBuffer buffer, VkDeviceAddress address);
  void Destroyed(VkBuffer buffer);
  bool HasAddress(VkBuffer buffer) const;

  // The buffer holding [address, address + bytes), and the offset of `address` in it.
  bool Find(VkDeviceAddress address, VkDeviceSize bytes, VkBuffer* buffer, VkDeviceSize* offset) const;

 private:
  struct Buffer {
    VkDeviceSize size = 0;
    bool addressable = false;
    VkDeviceAddress address = 0;
  };
  mutable std::mutex lock_;
  std::unordered_map<VkBuffer, Buffer> buffers_;
  std::multimap<VkDeviceAddress, VkBuffer> by_address_;
};

}  // namespace asval_test_driver
