#pragma once
// VK_NV_ray_tracing_motion_blur (spec version 1) over a driver without it (lavapipe), so that the layers above can
// validate KHR acceleration-structure creates and builds that use motion (the build flag needs a structure created
// with the create flag). What the driver below builds is the same work without motion: no motion result is ever
// produced, and nothing here traces.
//
// The extension is listed and kept from the driver below by device_extensions.h. Its features structure is reported
// (test_driver_api.h: rayTracingMotionBlur VK_TRUE, rayTracingMotionBlurPipelineTraceRaysIndirect VK_FALSE) and kept
// out of the chains the driver below reads (StructureOutOfChain, chain_edits.h): the extension is not the driver's, so
// the structure is not valid there (lavapipe 25.0 tolerates it: it answers VK_FALSE, and ignores it in vkCreateDevice
// even when it asks for VK_TRUE).
//
// For a device that enables the extension, the driver below gets copies without motion:
// - vkCreateAccelerationStructureKHR: createFlags without VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV, pNext without
//   VkAccelerationStructureMotionInfoNV;
// - vkCmdBuildAccelerationStructuresKHR, vkBuildAccelerationStructuresKHR (host_commands.h),
//   vkCmdBuildAccelerationStructuresIndirectKHR (indirect_builds.h) and vkGetAccelerationStructureBuildSizesKHR: flags
//   without VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV, each triangles geometry's pNext without
//   VkAccelerationStructureGeometryMotionTrianglesDataNV (BuildInfosBelow, build_infos_below.h). A bottom level with
//   motion triangles is built as a static one of its first vertex set (vertexData), sized as such, and its second
//   vertex set is never read.
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

namespace asval_test_driver {

// vkGetPhysicalDeviceFeatures2: the test driver's values in a VkPhysicalDeviceRayTracingMotionBlurFeaturesNV of the
// chain, if any.
void ReportMotionBlurFeatures(void* chain);

// The device command the test driver implements only for VK_NV_ray_tracing_motion_blur
// (vkCreateAccelerationStructureKHR), or nullptr for any other name. It goes straight down for a device that did not
// enable the extension. (vkCmdBuildAccelerationStructuresKHR: build_infos_below.h.)
PFN_vkVoidFunction MotionBlurFunction(const char* name);

}  // namespace asval_test_driver
