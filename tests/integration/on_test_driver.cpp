#include "on_test_driver.h"

#include <stdexcept>

namespace asval_test {

std::string LayersWithTestDriver() {
  std::string list;
  for (const std::string& layer : vkkit::LayersFromEnvironment()) list += layer + ":";
  return list + "VK_LAYER_ASVAL_test_driver";
}

HeldSubmissions::HeldSubmissions(vkkit::Device& device)
    : device_(device),
      hold_(reinterpret_cast<PFN_vkAsvalTestDriverHoldSubmissions>(
          vkGetDeviceProcAddr(device.handle(), kAsvalTestDriverHoldSubmissions))) {
  if (!hold_) throw std::runtime_error("vkAsvalTestDriverHoldSubmissions: the test driver is not below the layers");
}

HeldSubmissions::~HeldSubmissions() {
  if (held_) Release();
}

VkResult HeldSubmissions::Submit(VkCommandBuffer cb) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  return vkQueueSubmit(device_.queue(), 1, &submit, VK_NULL_HANDLE);
}

VkResult HeldSubmissions::SubmitHeld(VkCommandBuffer cb) {
  if (!held_) {
    const VkResult held = hold_(device_.handle(), VK_TRUE);
    if (held != VK_SUCCESS) return held;
    held_ = true;
  }
  return Submit(cb);
}

VkResult HeldSubmissions::Release() {
  if (held_) {
    held_ = false;
    const VkResult released = hold_(device_.handle(), VK_FALSE);
    if (released != VK_SUCCESS) return released;
  }
  return vkQueueWaitIdle(device_.queue());
}

VkResult HeldSubmissions::SubmitAndWait(VkCommandBuffer cb) {
  const VkResult submitted = Submit(cb);
  return submitted != VK_SUCCESS ? submitted : vkQueueWaitIdle(device_.queue());
}

DeviceLocalStructure::DeviceLocalStructure(vkkit::Device& device, VkAccelerationStructureTypeKHR type,
                                           VkDeviceSize size)
    : device_(device) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  vkkit::Check(vkCreateBuffer(device.handle(), &info, nullptr, &buffer_), "vkCreateBuffer");
  VkMemoryRequirements needs{};
  vkGetBufferMemoryRequirements(device.handle(), buffer_, &needs);
  // Throws when the driver has no such type (not the test driver).
  const uint32_t type_index = device.FindMemoryType(needs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                                                    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  allocate.allocationSize = needs.size;
  allocate.memoryTypeIndex = type_index;
  vkkit::Check(vkAllocateMemory(device.handle(), &allocate, nullptr, &memory_), "vkAllocateMemory");
  vkkit::Check(vkBindBufferMemory(device.handle(), buffer_, memory_, 0), "vkBindBufferMemory");
  VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  create.buffer = buffer_;
  create.size = size;
  create.type = type;
  vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &create, nullptr, &structure_),
               "vkCreateAccelerationStructureKHR");
}

DeviceLocalStructure::~DeviceLocalStructure() {
  device_.DestroyAccelerationStructureKHR(device_.handle(), structure_, nullptr);
  vkDestroyBuffer(device_.handle(), buffer_, nullptr);
  vkFreeMemory(device_.handle(), memory_, nullptr);
}

}  // namespace asval_test
