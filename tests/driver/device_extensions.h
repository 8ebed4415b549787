#pragma once
// The device extensions the test driver adds over a driver without them (lavapipe): VK_NV_ray_tracing
// (nv_ray_tracing.h), VK_NV_ray_tracing_motion_blur (motion_blur.h) and VK_EXT_opacity_micromap (opacity_micromap.h).
// The layers above see them listed; the driver below is never asked to enable them (lavapipe refuses a device naming
// one: VK_ERROR_EXTENSION_NOT_PRESENT).
#include <vulkan/vulkan.h>

#include <vector>

namespace asval_test_driver {

// vkEnumerateDeviceExtensionProperties with pLayerName NULL: below's extensions and the added ones (each listed once,
// as the test driver's, should the driver below have one too), in the count and VK_INCOMPLETE protocol.
VkResult EnumerateDeviceExtensionsWithAdded(PFN_vkEnumerateDeviceExtensionProperties below, VkPhysicalDevice gpu,
                                            uint32_t* count, VkExtensionProperties* properties);

// vkCreateDevice's create info for the driver below: the application's, without the added extensions (one copy of the
// array: the application's stays as it gave it), and which of them the application enabled. Its pNext is the
// application's chain, which the test driver edits while the driver below creates the device (chain_edits.h).
class DeviceCreateWithoutAdded {
 public:
  explicit DeviceCreateWithoutAdded(const VkDeviceCreateInfo& info);
  DeviceCreateWithoutAdded(const DeviceCreateWithoutAdded&) = delete;
  DeviceCreateWithoutAdded& operator=(const DeviceCreateWithoutAdded&) = delete;

  VkDeviceCreateInfo* below() { return &info_; }
  bool nv_enabled() const { return nv_enabled_; }
  bool motion_blur_enabled() const { return motion_blur_enabled_; }
  bool opacity_micromap_enabled() const { return opacity_micromap_enabled_; }
  bool ray_tracing_pipeline_enabled() const { return ray_tracing_pipeline_enabled_; }

 private:
  std::vector<const char*> extensions_;
  VkDeviceCreateInfo info_{};
  bool nv_enabled_ = false;
  bool motion_blur_enabled_ = false;
  bool opacity_micromap_enabled_ = false;
  bool ray_tracing_pipeline_enabled_ = false;
};

}  // namespace asval_test_driver
