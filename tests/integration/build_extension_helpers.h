#pragma once
// Objects of the KHR builds' extensions that no local driver has (the test driver exposes them: tests/driver), for the
// integration tests and the corpus: structures created for motion (VK_NV_ray_tracing_motion_blur) and opacity
// micromaps (VK_EXT_opacity_micromap), and the device options that enable them.
#include <vulkan/vulkan.h>

#include <vector>

#include "vkkit.h"

namespace asval_test {

// VK_NV_ray_tracing_motion_blur (and VK_KHR_ray_tracing_pipeline, which it requires) with rayTracingMotionBlur.
struct MotionBlurDevice {
  MotionBlurDevice();
  MotionBlurDevice(const MotionBlurDevice&) = delete;
  VkPhysicalDeviceRayTracingMotionBlurFeaturesNV features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV};
  vkkit::DeviceOptions options;  // points at `features`
};

// VK_EXT_opacity_micromap with micromap.
struct OpacityMicromapDevice {
  OpacityMicromapDevice();
  OpacityMicromapDevice(const OpacityMicromapDevice&) = delete;
  VkPhysicalDeviceOpacityMicromapFeaturesEXT features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_FEATURES_EXT};
  vkkit::DeviceOptions options;  // points at `features`
};

// A bottom-level structure of 64 KiB on a buffer of its own, created with CREATE_MOTION_BIT_NV (and a
// VkAccelerationStructureMotionInfoNV) or without; destroyed with the object.
class MotionStructure {
 public:
  MotionStructure(vkkit::Device& device, bool motion);
  ~MotionStructure();
  MotionStructure(const MotionStructure&) = delete;
  MotionStructure& operator=(const MotionStructure&) = delete;
  VkAccelerationStructureKHR handle() const { return handle_; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer storage_;
  VkAccelerationStructureKHR handle_ = VK_NULL_HANDLE;
};

// Two triangles of a motion build: their vertices at time 0 and at time 1 in host-visible buffers of their own, a
// structure created for motion (or not: `motion` false builds without the flag, its geometry still chaining the time-1
// vertices), scratch; builds and updates in place, each submitted alone and waited for (the capture's findings are
// reported in the wait).
class MotionRefit {
 public:
  explicit MotionRefit(vkkit::Device& device, bool motion = true);
  ~MotionRefit();
  MotionRefit(const MotionRefit&) = delete;
  MotionRefit& operator=(const MotionRefit&) = delete;

  // Six vertices (two unit right triangles) moved by dx along X, into `buffer`.
  static void Write(vkkit::Buffer& buffer, float dx);
  // Triangle t's first vertex X at time 1 made NaN: with motion, the triangle is inactive (an X of any of its six
  // vertices).
  void NanAtTime1(uint32_t t);
  vkkit::Buffer& at_1() { return at_1_; }
  // A build, or an update in place, of both triangles, submitted and waited for: the layer's result.
  VkResult Run(bool update);
  // The same as a host build (vkBuildAccelerationStructuresKHR, host pointers to the same vertices; the device
  // enables accelerationStructureHostCommands).
  VkResult RunOnHost(bool update);

 private:
  vkkit::Device& device_;
  bool motion_;
  MotionStructure structure_;
  vkkit::Buffer at_0_, at_1_, scratch_;
  std::vector<unsigned char> host_scratch_ = std::vector<unsigned char>(1 << 20);

  // The build's info over `time_1` and `geometry` (which it points to), with device or host addresses.
  VkAccelerationStructureBuildGeometryInfoKHR Info(bool update, bool host,
                                                   VkAccelerationStructureGeometryMotionTrianglesDataNV& time_1,
                                                   VkAccelerationStructureGeometryKHR& geometry);
};

// An opacity micromap on a buffer of its own, never built (a build reading only special indices does not need its
// contents); destroyed with the object.
class Micromap {
 public:
  explicit Micromap(vkkit::Device& device);
  ~Micromap();
  Micromap(const Micromap&) = delete;
  Micromap& operator=(const Micromap&) = delete;
  VkMicromapEXT handle() const { return handle_; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer storage_;
  PFN_vkDestroyMicromapEXT destroy_ = nullptr;
  VkMicromapEXT handle_ = VK_NULL_HANDLE;
};

// A buffer whose first 4 bytes hold VK_OPACITY_MICROMAP_SPECIAL_INDEX_FULLY_OPAQUE_EXT as a uint32 (a micromap index a
// build reads without the micromap's contents).
vkkit::Buffer SpecialIndexBuffer(vkkit::Device& device);

// A triangle's opacity from `micromap`, by 32-bit special indices read from `indices`, `stride` bytes apart.
VkAccelerationStructureTrianglesOpacityMicromapEXT OpacityFromSpecialIndices(const vkkit::Buffer& indices,
                                                                             const Micromap& micromap,
                                                                             VkDeviceSize stride = 4);

}  // namespace asval_test
