#pragma once
// The scene's VK_EXT_debug_utils messenger: prints every validation message (from asval, or from any layer
// stacked with it), counts them, and, as the Khronos test framework does, returns VK_TRUE for errors so
// that the layer skips the invalid call instead of passing it to the driver.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace scene {

struct Finding {
  bool error = false;
  std::string vuid;
  std::string message;
};

class Findings {
 public:
  // The create info to chain into VkInstanceCreateInfo (so create-time messages arrive too) and to pass to
  // vkCreateDebugUtilsMessengerEXT.
  VkDebugUtilsMessengerCreateInfoEXT CreateInfo();
  void Attach(VkInstance instance);  // creates the messenger
  void Detach();                     // destroys it (before the instance)

  // A layer may report from its own threads (checks that wait for the GPU), hence the lock.
  uint32_t errors() const;
  uint32_t warnings() const;
  std::vector<Finding> all() const;

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL Callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT types,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  mutable std::mutex mutex_;
  uint32_t errors_ = 0;
  uint32_t warnings_ = 0;
  std::vector<Finding> all_;
};

}  // namespace scene
