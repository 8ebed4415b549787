#pragma once
// Monitor: the test side of VK_EXT_debug_utils, in the style of the Khronos layer's ErrorMonitor. A test
// says which VUIDs it expects from the next operation; any other message fails the test at Verify().
// Expected errors make the callback return VK_TRUE, so the layer keeps the invalid call away from the driver.
#include <vulkan/vulkan.h>

#include <mutex>
#include <string>
#include <vector>

namespace asval_test {

struct Message {
  VkDebugUtilsMessageSeverityFlagBitsEXT severity;
  std::string id_name;
  int32_t id_number;
  std::string text;
  std::vector<VkDebugUtilsObjectNameInfoEXT> objects;  // pObjectName copied into names
  std::vector<std::string> names;
};

class Monitor {
 public:
  Monitor();
  // Chain into VkInstanceCreateInfo::pNext (create-time messages) and pass to vkCreateDebugUtilsMessengerEXT.
  const VkDebugUtilsMessengerCreateInfoEXT& create_info() const { return create_info_; }

  void Expect(const std::string& vuid, int count = 1);
  // Checks that each expected VUID was seen exactly as often as expected and nothing else was; clears.
  // Returns a description of what was wrong, empty when all is well.
  std::string Verify();
  // Everything received since the last Verify/Take (for tests that inspect the callback data).
  std::vector<Message> Take();

  // Messages to ignore entirely (e.g. the loader's own informational chatter).
  void Ignore(const std::string& id_prefix) { ignored_.push_back(id_prefix); }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL Callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT types,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  VkDebugUtilsMessengerCreateInfoEXT create_info_{};
  std::mutex mutex_;
  std::vector<std::pair<std::string, int>> expected_;
  std::vector<Message> received_;
  std::vector<std::string> ignored_;
};

}  // namespace asval_test
