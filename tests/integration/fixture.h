#pragma once
// A Vulkan instance + ray-tracing device under the layers named by ASVAL_TEST_LAYERS (default: asval alone),
// with a Monitor attached both at instance creation (pNext) and as a created messenger.
#include <memory>

#include "monitor.h"
#include "vkkit.h"

namespace asval_test {

class Fixture {
 public:
  // extra_pnext is chained after the monitor's create info (e.g. a VkLayerSettingsCreateInfoEXT).
  explicit Fixture(const void* extra_pnext = nullptr);
  ~Fixture();

  Monitor& monitor() { return *monitor_; }
  vkkit::Instance& instance() { return *instance_; }
  vkkit::Device& device() { return *device_; }

 private:
  std::unique_ptr<Monitor> monitor_;
  VkDebugUtilsMessengerCreateInfoEXT pnext_info_{};
  std::unique_ptr<vkkit::Instance> instance_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::unique_ptr<vkkit::Device> device_;
};

}  // namespace asval_test
