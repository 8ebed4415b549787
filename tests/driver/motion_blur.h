#pragma once
// VK_NV_ray_tracing_motion_blur (spec version 1) over a driver without it (lavapipe), so that the layers above can
// validate KHR acceleration-structure creates and builds that use motion (the build flag needs a structure created
// with the create flag). What the driver below builds is the same work without motion: no motion result is ever
// produced, and nothing here traces.
//
// The extension is listed and kept from the driver below by device_extensions.h. Its features structure is reported
// (test_driver_api.h: rayTracingMotionBlur VK_TRUE, rayTracingMotionBlurPipelineTraceRaysIndirect VK_FALSE) and kept
// out of the chains the driver below reads: the extension is not the driver's, so the structure is not valid there
// (lavapipe 25.0 tolerates it: it answers VK_FALSE, and ignores it in vkCreateDevice even when it asks for VK_TRUE).
//
// For a device that enables the extension, the driver below gets copies without motion:
// - vkCreateAccelerationStructureKHR: createFlags without VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV, pNext without
//   VkAccelerationStructureMotionInfoNV;
// - vkCmdBuildAccelerationStructuresKHR, vkBuildAccelerationStructuresKHR (host_commands.h),
//   vkCmdBuildAccelerationStructuresIndirectKHR (indirect_builds.h) and vkGetAccelerationStructureBuildSizesKHR: flags
//   without VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV, each triangles geometry's pNext without
//   VkAccelerationStructureGeometryMotionTrianglesDataNV. A bottom level with motion triangles is built as a static one
//   of its first vertex set (vertexData), sized as such, and its second vertex set is never read.
// The application's structures, arrays and chains stay as it gave them. (Lavapipe 25.0 ignores these flags and
// structures when given them, but the copies keep the driver below to what it has.)
//
// Not supported: a top level of motion instances (VkAccelerationStructureMotionInstanceNV, 152 bytes each at a 160-byte
// stride). Its build goes down with its ranges untouched, so the driver below reads the records as 64-byte
// VkAccelerationStructureInstanceKHR ones, whose bottom-level references are then other bytes, which lavapipe (a CPU
// driver) follows as addresses: tests must not build motion top levels on lavapipe. Pipelines created with
// VK_PIPELINE_CREATE_RAY_TRACING_ALLOW_MOTION_BIT_NV and traceRayMotionNV reach the driver below as given.
//
// A device that does not enable the extension sees none of this: its creates and builds reach the driver below as
// the application gave them.
#include <vulkan/vulkan.h>

#include <memory>
#include <vector>

namespace asval_test_driver {

// A VkPhysicalDeviceRayTracingMotionBlurFeaturesNV in a chain the driver below reads (vkGetPhysicalDeviceFeatures2's,
// vkCreateDevice's): out of the chain while it does, then put back where it was. Only the chain's links change: the
// structure itself, and the others, are left as they are.
class MotionBlurFeaturesOutOfChain {
 public:
  explicit MotionBlurFeaturesOutOfChain(void* head);  // the structure whose pNext chain is searched
  ~MotionBlurFeaturesOutOfChain();
  MotionBlurFeaturesOutOfChain(const MotionBlurFeaturesOutOfChain&) = delete;
  MotionBlurFeaturesOutOfChain& operator=(const MotionBlurFeaturesOutOfChain&) = delete;

 private:
  VkBaseOutStructure* before_ = nullptr;  // the structure whose pNext it was
  VkBaseOutStructure* features_ = nullptr;
};

// vkGetPhysicalDeviceFeatures2: the test driver's values in a VkPhysicalDeviceRayTracingMotionBlurFeaturesNV of the
// chain, if any.
void ReportMotionBlurFeatures(void* chain);

// A pNext chain for the driver below without the structures of one type; the application's structures are left as
// they are. Those after the last one taken out are the application's own; a structure before it needs a copy (its
// pNext changes), which is made for VkOpaqueCaptureDescriptorDataCreateInfoEXT, the one that can come before
// VkAccelerationStructureMotionInfoNV on lavapipe, and any other is left out (a triangles geometry's chain can hold
// only micromap structures besides the motion one, and lavapipe has no micromaps).
class ChainWithout {
 public:
  ChainWithout(const void* chain, VkStructureType type);
  const void* head() const { return head_; }

 private:
  std::vector<std::unique_ptr<unsigned char[]>> copies_;
  const void* head_ = nullptr;
};

// The build geometry infos the driver below gets: the application's where the device did not enable the extension,
// else copies without motion (above), their geometries copied into arrays of their own (pGeometries, whichever the
// application used). The chains in them are the application's structures (ChainWithout copies none of a triangles
// chain), so a copy of these infos that outlives this object (an indirect build's) is valid as long as theirs.
class BuildInfosBelow {
 public:
  BuildInfosBelow(bool motion_blur, uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos);
  BuildInfosBelow(const BuildInfosBelow&) = delete;
  BuildInfosBelow& operator=(const BuildInfosBelow&) = delete;

  const VkAccelerationStructureBuildGeometryInfoKHR* get() const { return infos_; }

 private:
  const VkAccelerationStructureBuildGeometryInfoKHR* infos_;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> copies_;
  std::vector<std::vector<VkAccelerationStructureGeometryKHR>> geometries_;
  std::vector<ChainWithout> chains_;
};

// The device commands the test driver implements only for VK_NV_ray_tracing_motion_blur
// (vkCreateAccelerationStructureKHR, vkCmdBuildAccelerationStructuresKHR), or nullptr for any other name. They go
// straight down for a device that did not enable the extension.
PFN_vkVoidFunction MotionBlurFunction(const char* name);

}  // namespace asval_test_driver
