#include "device_buffers.h"

#include <cstring>

namespace refit {

vkkit::Buffer CreateDeviceLocalBuffer(vkkit::Device& device, VkDeviceSize size, VkBufferUsageFlags usage) {
  vkkit::Buffer b;
  b.size = size;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  vkkit::Check(vkCreateBuffer(device.handle(), &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device.handle(), b.buffer, &req);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = device.FindMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  vkkit::Check(vkAllocateMemory(device.handle(), &alloc, nullptr, &b.memory), "vkAllocateMemory");
  vkkit::Check(vkBindBufferMemory(device.handle(), b.buffer, b.memory, 0), "vkBindBufferMemory");
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, b.buffer};
  b.address = vkGetBufferDeviceAddress(device.handle(), &address);
  return b;
}

vkkit::Buffer UploadToDevice(vkkit::Device& device, const void* bytes, VkDeviceSize size, VkBufferUsageFlags usage) {
  vkkit::Buffer staging = device.CreateBuffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(staging.mapped, bytes, size);
  vkkit::Buffer target = CreateDeviceLocalBuffer(device, size, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  device.OneShot([&](VkCommandBuffer cb) {
    const VkBufferCopy region{0, 0, size};
    vkCmdCopyBuffer(cb, staging.buffer, target.buffer, 1, &region);
  });
  device.Destroy(staging);
  return target;
}

}  // namespace refit
