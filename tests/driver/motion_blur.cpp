#include "motion_blur.h"

#include <cstring>

#include "driver_dispatch.h"
#include "test_driver_api.h"

namespace asval_test_driver {
namespace {

// The size of a structure ChainWithout copies, or 0 for one it leaves out.
size_t CopiedSize(VkStructureType type) {
  switch (type) {
    case VK_STRUCTURE_TYPE_OPAQUE_CAPTURE_DESCRIPTOR_DATA_CREATE_INFO_EXT:
      return sizeof(VkOpaqueCaptureDescriptorDataCreateInfoEXT);
    default:
      return 0;
  }
}

}  // namespace

MotionBlurFeaturesOutOfChain::MotionBlurFeaturesOutOfChain(void* head) {
  for (auto* s = static_cast<VkBaseOutStructure*>(head); s->pNext != nullptr; s = s->pNext) {
    if (s->pNext->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV) {
      before_ = s;
      features_ = s->pNext;
      before_->pNext = features_->pNext;
      return;
    }
  }
}

MotionBlurFeaturesOutOfChain::~MotionBlurFeaturesOutOfChain() {
  if (features_ != nullptr) before_->pNext = features_;  // its own pNext was left as it was
}

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

ChainWithout::ChainWithout(const void* chain, VkStructureType type) : head_(chain) {
  const VkBaseInStructure* last = nullptr;
  for (auto* s = static_cast<const VkBaseInStructure*>(chain); s != nullptr; s = s->pNext) {
    if (s->sType == type) last = s;
  }
  if (last == nullptr) return;
  std::vector<const VkBaseInStructure*> kept;  // before `last`
  for (auto* s = static_cast<const VkBaseInStructure*>(chain); s != last; s = s->pNext) {
    if (s->sType != type && CopiedSize(s->sType) != 0) kept.push_back(s);
  }
  head_ = last->pNext;
  for (auto s = kept.rbegin(); s != kept.rend(); ++s) {  // linked from the end
    const size_t size = CopiedSize((*s)->sType);
    copies_.push_back(std::make_unique<unsigned char[]>(size));
    std::memcpy(copies_.back().get(), *s, size);
    reinterpret_cast<VkBaseInStructure*>(copies_.back().get())->pNext = static_cast<const VkBaseInStructure*>(head_);
    head_ = copies_.back().get();
  }
}

BuildInfosBelow::BuildInfosBelow(bool motion_blur, uint32_t count,
                                 const VkAccelerationStructureBuildGeometryInfoKHR* infos)
    : infos_(infos) {
  if (!motion_blur) return;
  copies_.assign(infos, infos + count);
  geometries_.resize(count);  // not resized again: the arrays the copies point to stay where they are
  for (uint32_t i = 0; i < count; ++i) {
    VkAccelerationStructureBuildGeometryInfoKHR& info = copies_[i];
    info.flags &= ~static_cast<VkBuildAccelerationStructureFlagsKHR>(VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV);
    std::vector<VkAccelerationStructureGeometryKHR>& geometries = geometries_[i];
    for (uint32_t g = 0; g < info.geometryCount; ++g) {
      geometries.push_back(info.pGeometries != nullptr ? info.pGeometries[g] : *info.ppGeometries[g]);
      VkAccelerationStructureGeometryKHR& geometry = geometries.back();
      if (geometry.geometryType != VK_GEOMETRY_TYPE_TRIANGLES_KHR) continue;
      chains_.emplace_back(geometry.geometry.triangles.pNext,
                           VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV);
      geometry.geometry.triangles.pNext = chains_.back().head();
    }
    info.pGeometries = geometries.empty() ? nullptr : geometries.data();
    info.ppGeometries = nullptr;
  }
  infos_ = copies_.data();
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
  const ChainWithout chain(info->pNext, VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MOTION_INFO_NV);
  below.pNext = chain.head();
  return device->vk.CreateAccelerationStructureKHR(handle, &below, allocator, structure);
}

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructuresKHR(
    VkCommandBuffer command_buffer, uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
    const VkAccelerationStructureBuildRangeInfoKHR* const* ranges) {
  DeviceData* device = FindDevice(command_buffer);
  const BuildInfosBelow below(device->motion_blur, count, infos);
  device->vk.CmdBuildAccelerationStructuresKHR(command_buffer, count, below.get(), ranges);
}

}  // namespace

PFN_vkVoidFunction MotionBlurFunction(const char* name) {
#define ASVAL_DRIVER_MOTION_HOOK(fn) \
  if (std::strcmp(name, "vk" #fn) == 0) return reinterpret_cast<PFN_vkVoidFunction>(&fn);
  ASVAL_DRIVER_MOTION_HOOK(CreateAccelerationStructureKHR)
  ASVAL_DRIVER_MOTION_HOOK(CmdBuildAccelerationStructuresKHR)
#undef ASVAL_DRIVER_MOTION_HOOK
  return nullptr;
}

}  // namespace asval_test_driver
