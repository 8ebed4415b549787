#include "queue_family.h"

#include <stdexcept>
#include <vector>

namespace refit {

uint32_t DeviceQueueFamily(VkPhysicalDevice gpu, VkQueueFamilyProperties* properties) {
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(gpu, &count, families.data());
  for (uint32_t i = 0; i < count; ++i) {
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      if (properties) *properties = families[i];
      return i;
    }
  }
  throw std::runtime_error("no queue family with compute");
}

}  // namespace refit
