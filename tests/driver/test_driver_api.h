#pragma once
// The test driver's own entry points, for tests (reached through vkGetDeviceProcAddr: the layers above pass names they
// do not know down the chain), and what it reports for the extensions it adds, for tests to compare with.
#include <vulkan/vulkan.h>

#include <cstdint>

// While `hold` is VK_TRUE, the device's submissions wait for the test driver to release them (VK_FALSE): work the
// layers above see submitted with no wait, and pending as long as the test needs (submission_hold.h).
extern "C" typedef VkResult(VKAPI_PTR* PFN_vkAsvalTestDriverHoldSubmissions)(VkDevice device, VkBool32 hold);
inline constexpr const char kAsvalTestDriverHoldSubmissions[] = "vkAsvalTestDriverHoldSubmissions";

// VK_NV_ray_tracing, which the test driver reports and implements itself over a driver without it (nv_ray_tracing.h),
// so that the layers above see and validate the NV acceleration-structure commands. Nothing is executed: the
// structures' contents are never produced, and a property write leaves its query as reset (lavapipe reads it as 0).
inline constexpr uint32_t kAsvalTestDriverNvRayTracingSpecVersion = 3;

// VkPhysicalDeviceRayTracingPropertiesNV as reported. maxGeometryCount is small on purpose: a test can exceed it.
inline constexpr uint32_t kAsvalTestDriverNvShaderGroupHandleSize = 32;
inline constexpr uint32_t kAsvalTestDriverNvMaxRecursionDepth = 31;
inline constexpr uint32_t kAsvalTestDriverNvMaxShaderGroupStride = 4096;
inline constexpr uint32_t kAsvalTestDriverNvShaderGroupBaseAlignment = 64;
inline constexpr uint64_t kAsvalTestDriverNvMaxGeometryCount = 64;
inline constexpr uint64_t kAsvalTestDriverNvMaxInstanceCount = uint64_t{1} << 24;
inline constexpr uint64_t kAsvalTestDriverNvMaxTriangleCount = uint64_t{1} << 29;
inline constexpr uint32_t kAsvalTestDriverNvMaxDescriptorSetAccelerationStructures = 16;

// vkGetAccelerationStructureMemoryRequirementsNV: every size is aligned to this, memoryTypeBits names every memory type
// of the device (the added one included: memory_types.h), and no dedicated allocation is asked for.
inline constexpr VkDeviceSize kAsvalTestDriverNvMemoryAlignment = 256;

// The primitives P a structure is sized for: a top level's instanceCount; for a bottom level, the sum over its
// geometries of indexCount / 3 (indexType not VK_INDEX_TYPE_NONE_NV) or vertexCount / 3 (triangles), numAABBs (AABBs).
constexpr uint64_t AsvalTestDriverNvPrimitives(const VkAccelerationStructureInfoNV& info) {
  if (info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV) return info.instanceCount;
  uint64_t primitives = 0;
  for (uint32_t i = 0; i < info.geometryCount; ++i) {
    const VkGeometryNV& g = info.pGeometries[i];
    if (g.geometryType == VK_GEOMETRY_TYPE_AABBS_NV) {
      primitives += g.geometry.aabbs.numAABBs;
    } else {
      const VkGeometryTrianglesNV& t = g.geometry.triangles;
      primitives += (t.indexType != VK_INDEX_TYPE_NONE_NV ? t.indexCount : t.vertexCount) / 3;
    }
  }
  return primitives;
}

// The size of one memory requirement for P primitives: OBJECT 1024 + 128 P rounded up to the alignment, BUILD_SCRATCH
// 512 + 64 P, UPDATE_SCRATCH 256 + 32 P. A structure created with a compactedSize (no geometries nor instances, as
// VkAccelerationStructureCreateInfoNV requires: a compacting copy's destination) has OBJECT compactedSize rounded up to
// the alignment, and the scratch sizes of P = 0.
constexpr VkDeviceSize AsvalTestDriverNvMemorySize(VkAccelerationStructureMemoryRequirementsTypeNV type,
                                                   uint64_t primitives, VkDeviceSize compacted_size = 0) {
  const auto aligned = [](VkDeviceSize size) {
    return (size + kAsvalTestDriverNvMemoryAlignment - 1) / kAsvalTestDriverNvMemoryAlignment *
           kAsvalTestDriverNvMemoryAlignment;
  };
  if (compacted_size != 0) primitives = 0;
  switch (type) {
    case VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV:
      return 512 + 64 * primitives;
    case VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV:
      return 256 + 32 * primitives;
    default:  // OBJECT
      return compacted_size != 0 ? aligned(compacted_size) : aligned(1024 + 128 * primitives);
  }
}

// VK_NV_ray_tracing_motion_blur, which the test driver reports over a driver without it (motion_blur.h), so that the
// layers above validate KHR structures and builds that use motion. Motion is not built: for a device that enables the
// extension, creates and builds reach the driver below without their motion flags and structures (a bottom level with
// motion triangles is built from its first vertex set), and a top level of motion instances is not supported.
inline constexpr uint32_t kAsvalTestDriverMotionBlurSpecVersion = 1;

// VkPhysicalDeviceRayTracingMotionBlurFeaturesNV as reported (the features a device may enable).
inline constexpr VkBool32 kAsvalTestDriverRayTracingMotionBlur = VK_TRUE;
inline constexpr VkBool32 kAsvalTestDriverRayTracingMotionBlurPipelineTraceRaysIndirect = VK_FALSE;

// VK_EXT_opacity_micromap, which the test driver reports over a driver without it (opacity_micromap.h), so that the
// layers above validate KHR builds whose triangles carry VkAccelerationStructureTrianglesOpacityMicromapEXT. Micromaps
// are not executed: builds reach the driver below without the structure and the opacity-micromap build flags, and the
// driver's own micromap objects have no contents.
inline constexpr uint32_t kAsvalTestDriverOpacityMicromapSpecVersion = 2;

// VkPhysicalDeviceOpacityMicromapFeaturesEXT as reported (the features a device may enable).
inline constexpr VkBool32 kAsvalTestDriverMicromap = VK_TRUE;
inline constexpr VkBool32 kAsvalTestDriverMicromapCaptureReplay = VK_FALSE;
inline constexpr VkBool32 kAsvalTestDriverMicromapHostCommands = VK_FALSE;

// VkPhysicalDeviceOpacityMicromapPropertiesEXT as reported.
inline constexpr uint32_t kAsvalTestDriverMaxOpacity2StateSubdivisionLevel = 12;
inline constexpr uint32_t kAsvalTestDriverMaxOpacity4StateSubdivisionLevel = 12;

// vkGetMicromapBuildSizesEXT: micromapSize 256 + 64 T, where T is the sum of the counts of the build info's usage
// counts (pUsageCounts or ppUsageCounts), buildScratchSize kAsvalTestDriverMicromapBuildScratchSize, discardable
// VK_FALSE.
inline constexpr VkDeviceSize kAsvalTestDriverMicromapBuildScratchSize = 256;
constexpr VkDeviceSize AsvalTestDriverMicromapSize(const VkMicromapBuildInfoEXT& info) {
  VkDeviceSize triangles = 0;
  for (uint32_t i = 0; i < info.usageCountsCount; ++i) {
    triangles += info.pUsageCounts != nullptr ? info.pUsageCounts[i].count : info.ppUsageCounts[i]->count;
  }
  return 256 + 64 * triangles;
}
