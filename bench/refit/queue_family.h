#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>

namespace refit {

// The queue family vkkit::Device takes its queue from (the first with compute), and its properties.
uint32_t DeviceQueueFamily(VkPhysicalDevice gpu, VkQueueFamilyProperties* properties = nullptr);

}  // namespace refit
