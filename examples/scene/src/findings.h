#pragma once
// The scene's VK_EXT_debug_utils messenger: prints every validation message (from asval, or from any layer
// stacked with it) and counts them. It returns VK_FALSE, as a CI application without a test framework does: it
// never asks a layer to skip a call. What keeps a fault's invalid command from the driver is asval's protect mode
// (main.cpp turns it on for a fault run), whose ASVAL-Protect-Withheld information messages the messenger then
// listens to as well: the injector submits a hang-prone fault only after asval announced it withheld it.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace scene {

// The id of asval's notice for a call it withheld in protect mode (layer/checks/protect_notices.h).
inline constexpr const char kWithheldNoticeId[] = "ASVAL-Protect-Withheld";

struct Finding {
  bool error = false;
  bool info = false;
  std::string vuid;
  std::string message;
};

class Findings {
 public:
  // The create info to chain into VkInstanceCreateInfo (so create-time messages arrive too) and to pass to
  // vkCreateDebugUtilsMessengerEXT.
  // `notices`: information messages too (a fault run; a plain run listens to warnings and errors only).
  VkDebugUtilsMessengerCreateInfoEXT CreateInfo(bool notices);
  void Attach(VkInstance instance, bool notices);  // creates the messenger
  void Detach();                     // destroys it (before the instance)

  // A layer may report from its own threads (checks that wait for the GPU), hence the lock.
  uint32_t errors() const;
  uint32_t warnings() const;
  uint32_t infos() const;             // information messages, the notices below included
  uint32_t withheld_notices() const;  // ASVAL-Protect-Withheld: a call asval kept from the driver
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
  uint32_t infos_ = 0;
  uint32_t withheld_notices_ = 0;
  std::vector<Finding> all_;
};

}  // namespace scene
