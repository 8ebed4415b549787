#pragma once
// VK_EXT_opacity_micromap (spec version 2) over a driver without it (lavapipe), as far as acceleration-structure builds
// need, so that the layers above can validate VkAccelerationStructureTrianglesOpacityMicromapEXT in a triangles
// geometry (index type, index stride, usage counts). Nothing about opacity is ever built or traced.
//
// The extension is listed and kept from the driver below by device_extensions.h. Its features structure is reported
// (micromap VK_TRUE, micromapCaptureReplay and micromapHostCommands VK_FALSE) and its properties structure too (both
// subdivision levels 12: test_driver_api.h); both are kept out of the chains the driver below reads (chain_edits.h),
// as the extension is not the driver's.
//
// For a device that enables the extension, builds and build sizes reach the driver below without the structure and
// the opacity-micromap build flags (build_infos_below.h): the triangles are built as if they had no micromap, all of
// them opaque or not as their geometry flags say. Instances' VK_GEOMETRY_INSTANCE_FORCE_OPACITY_MICROMAP_2_STATE_EXT
// and VK_GEOMETRY_INSTANCE_DISABLE_OPACITY_MICROMAPS_EXT, read from buffers, and pipelines'
// VK_PIPELINE_CREATE_RAY_TRACING_OPACITY_MICROMAP_BIT_EXT reach the driver below as given (lavapipe ignores them).
//
// Micromap objects are the test driver's own, so that a build can name one: heap objects whose handle is their
// address, which keep their create info (pNext dropped) and nothing else; vkGetMicromapBuildSizesEXT answers the
// documented formula of test_driver_api.h, and vkCmdBuildMicromapsEXT records nothing. Not implemented (the names go
// down the chain, where the driver has none): the copies, serialization, compatibility queries, property writes and
// every host command (vkBuildMicromapsEXT and the others; micromapHostCommands is VK_FALSE).
//
// A device that does not enable the extension sees none of this: its vkGetDeviceProcAddr goes down the chain for the
// micromap names, and its builds reach the driver below as the application gave them.
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>
#include <unordered_map>

#include "chain_edits.h"

namespace asval_test_driver {

// vkGetPhysicalDeviceFeatures2: the test driver's values in a VkPhysicalDeviceOpacityMicromapFeaturesEXT of the chain,
// if any.
void ReportOpacityMicromapFeatures(void* chain);

// vkCreateBuffer's usage for the driver below: without VK_BUFFER_USAGE_MICROMAP_BUILD_INPUT_READ_ONLY_BIT_EXT and
// VK_BUFFER_USAGE_MICROMAP_STORAGE_BIT_EXT where the device enabled the extension (they are not the driver's; a usage
// left empty becomes VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, as an empty one is not valid), else as given.
VkBufferUsageFlags MicromapUsageBelow(bool enabled, VkBufferUsageFlags usage);

// A VkPhysicalDeviceOpacityMicromapPropertiesEXT in a vkGetPhysicalDeviceProperties2 chain: out of the chain while the
// driver below fills the others, then put back, filled with the test driver's limits.
class OpacityMicromapProperties {
 public:
  explicit OpacityMicromapProperties(VkPhysicalDeviceProperties2* properties);
  ~OpacityMicromapProperties();
  OpacityMicromapProperties(const OpacityMicromapProperties&) = delete;
  OpacityMicromapProperties& operator=(const OpacityMicromapProperties&) = delete;

 private:
  StructureOutOfChain out_;
};

// One device's micromaps.
class Micromaps {
 public:
  Micromaps();
  ~Micromaps();  // micromaps the application did not destroy go with the device
  Micromaps(const Micromaps&) = delete;
  Micromaps& operator=(const Micromaps&) = delete;

  VkResult Create(const VkMicromapCreateInfoEXT& info, VkMicromapEXT* micromap);
  void Destroy(VkMicromapEXT micromap);

 private:
  struct Micromap {
    VkMicromapCreateInfoEXT info{};  // pNext dropped
  };

  std::mutex lock_;
  std::unordered_map<VkMicromapEXT, std::unique_ptr<Micromap>> micromaps_;
};

// The device commands the test driver implements for VK_EXT_opacity_micromap (vkCreateMicromapEXT,
// vkDestroyMicromapEXT, vkGetMicromapBuildSizesEXT, vkCmdBuildMicromapsEXT), or nullptr for any other name.
PFN_vkVoidFunction OpacityMicromapFunction(const char* name);

}  // namespace asval_test_driver
