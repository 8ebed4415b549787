#include "motion_blur.h"

#include <cstring>

#include "chain_edits.h"
#include "driver_dispatch.h"
#include "test_driver_api.h"

namespace asval_test_driver {

void ReportMotionBlurFeatures(void* chain) {
  for (auto* s = static_cast<VkBaseOutStructure*>(chain); s != nullptr; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV) {
      auto* features = reinterpret_cast<VkPhysicalDeviceRayTracingMotionBlurFeaturesNV*>(s);
      features->rayTracingMotionBlur = kAsvalTestDriverRayTracingMotionBlur;
      features->rayTracingMotionBlurPipelineTraceRaysIndirect =
          kAsvalTestDriverRayTracingMotionBlurPipelineTraceRaysIndirect;
    }
  }
}

namespace {

VKAPI_ATTR VkResult VKAPI_CALL CreateAccelerationStructureKHR(VkDevice handle,
                                                              const VkAccelerationStructureCreateInfoKHR* info,
                                                              const VkAllocationCallbacks* allocator,
                                                              VkAccelerationStructureKHR* structure) {
  DeviceData* device = FindDevice(handle);
  if (!device->motion_blur) return device->vk.CreateAccelerationStructureKHR(handle, info, allocator, structure);
  VkAccelerationStructureCreateInfoKHR below = *info;
  below.createFlags &=
      ~static_cast<VkAccelerationStructureCreateFlagsKHR>(VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV);
  const ChainWithout chain(info->pNext, {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MOTION_INFO_NV});
  below.pNext = chain.head();
  return device->vk.CreateAccelerationStructureKHR(handle, &below, allocator, structure);
}

}  // namespace

PFN_vkVoidFunction MotionBlurFunction(const char* name) {
#define ASVAL_DRIVER_MOTION_HOOK(fn) \
  if (std::strcmp(name, "vk" #fn) == 0) return reinterpret_cast<PFN_vkVoidFunction>(&fn);
  ASVAL_DRIVER_MOTION_HOOK(CreateAccelerationStructureKHR)
#undef ASVAL_DRIVER_MOTION_HOOK
  return nullptr;
}

}  // namespace asval_test_driver
