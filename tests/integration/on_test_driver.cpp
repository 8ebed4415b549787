#include "on_test_driver.h"

namespace asval_test {

std::string LayersWithTestDriver() {
  std::string list;
  for (const std::string& layer : vkkit::LayersFromEnvironment()) list += layer + ":";
  return list + "VK_LAYER_ASVAL_test_driver";
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
