#include "device_extensions.h"

#include <algorithm>
#include <cstring>

#include "test_driver_api.h"

namespace asval_test_driver {
namespace {

struct Added {
  const char* name;
  uint32_t spec_version;
};
constexpr Added kAdded[] = {
    {VK_NV_RAY_TRACING_EXTENSION_NAME, kAsvalTestDriverNvRayTracingSpecVersion},
    {VK_NV_RAY_TRACING_MOTION_BLUR_EXTENSION_NAME, kAsvalTestDriverMotionBlurSpecVersion},
    {VK_EXT_OPACITY_MICROMAP_EXTENSION_NAME, kAsvalTestDriverOpacityMicromapSpecVersion},
};

bool IsAdded(const char* name) {
  return std::any_of(std::begin(kAdded), std::end(kAdded),
                     [name](const Added& added) { return std::strcmp(name, added.name) == 0; });
}

}  // namespace

VkResult EnumerateDeviceExtensionsWithAdded(PFN_vkEnumerateDeviceExtensionProperties below, VkPhysicalDevice gpu,
                                            uint32_t* count, VkExtensionProperties* properties) {
  std::vector<VkExtensionProperties> all;
  VkResult result;
  do {  // below's list may grow between the two calls
    uint32_t below_count = 0;
    result = below(gpu, nullptr, &below_count, nullptr);
    if (result != VK_SUCCESS) return result;
    all.resize(below_count);
    result = below(gpu, nullptr, &below_count, all.data());
    all.resize(below_count);
  } while (result == VK_INCOMPLETE);
  if (result != VK_SUCCESS) return result;
  all.erase(
      std::remove_if(all.begin(), all.end(), [](const VkExtensionProperties& e) { return IsAdded(e.extensionName); }),
      all.end());
  for (const Added& added : kAdded) {
    VkExtensionProperties extension{};
    std::strncpy(extension.extensionName, added.name, VK_MAX_EXTENSION_NAME_SIZE - 1);
    extension.specVersion = added.spec_version;
    all.push_back(extension);
  }

  const auto total = static_cast<uint32_t>(all.size());
  if (properties == nullptr) {
    *count = total;
    return VK_SUCCESS;
  }
  const uint32_t written = std::min(*count, total);
  std::copy(all.begin(), all.begin() + written, properties);
  *count = written;
  return written < total ? VK_INCOMPLETE : VK_SUCCESS;
}

DeviceCreateWithoutAdded::DeviceCreateWithoutAdded(const VkDeviceCreateInfo& info) : info_(info) {
  for (uint32_t i = 0; i < info.enabledExtensionCount; ++i) {
    const char* name = info.ppEnabledExtensionNames[i];
    if (std::strcmp(name, VK_NV_RAY_TRACING_EXTENSION_NAME) == 0) nv_enabled_ = true;
    if (std::strcmp(name, VK_NV_RAY_TRACING_MOTION_BLUR_EXTENSION_NAME) == 0) motion_blur_enabled_ = true;
    if (std::strcmp(name, VK_EXT_OPACITY_MICROMAP_EXTENSION_NAME) == 0) opacity_micromap_enabled_ = true;
    if (std::strcmp(name, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) == 0) ray_tracing_pipeline_enabled_ = true;
    if (!IsAdded(name)) extensions_.push_back(name);
  }
  info_.enabledExtensionCount = static_cast<uint32_t>(extensions_.size());
  info_.ppEnabledExtensionNames = extensions_.empty() ? nullptr : extensions_.data();
}

}  // namespace asval_test_driver
