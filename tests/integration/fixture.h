#pragma once
// A Vulkan instance + ray-tracing device under the layers named by ASVAL_TEST_LAYERS (default: asval alone),
// with a Monitor attached both at instance creation (pNext) and as a created messenger.
#include <memory>
#include <vector>

#include "layer_settings_ext.h"  // VK_EXT_layer_settings, newer than the 1.3.239 headers
#include "monitor.h"
#include "vkkit.h"

namespace asval_test {

// A VkLayerSettingsCreateInfoEXT for asval with string settings.
struct ApiSettings {
  std::vector<VkLayerSettingEXT> settings;
  std::vector<std::unique_ptr<const char*>> values;
  VkLayerSettingsCreateInfoEXT info{};

  void Add(const char* name, const char* value) {
    values.push_back(std::make_unique<const char*>(value));
    settings.push_back(VkLayerSettingEXT{"VK_LAYER_ASVAL_as_validation", name, VK_LAYER_SETTING_TYPE_STRING_EXT, 1,
                                         values.back().get()});
  }
  const void* Chain() {
    info.sType = VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT;
    info.settingCount = static_cast<uint32_t>(settings.size());
    info.pSettings = settings.data();
    return &info;
  }
};

class Fixture {
 public:
  // extra_pnext is chained after the monitor's create info (e.g. a VkLayerSettingsCreateInfoEXT); `device` says
  // what the device enables beyond vkkit's own.
  explicit Fixture(const void* extra_pnext = nullptr, const vkkit::DeviceOptions& device = {});
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
