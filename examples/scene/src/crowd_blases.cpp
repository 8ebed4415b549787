#include "crowd_blases.h"

#include <algorithm>
#include <string>

namespace scene {

CrowdBlases::CrowdBlases(Gpu& gpu, const DeformingBlases& deforming, uint32_t count)
    : gpu_(gpu), deforming_(deforming) {
  if (count == 0) return;  // the default scene: nothing created, nothing named
  const VkAccelerationStructureBuildSizesInfoKHR sizes = deforming.BlobInput(0).QuerySizes(gpu);
  const VkDeviceSize slice_alignment =
      std::max<VkDeviceSize>(128, gpu.as_properties().minAccelerationStructureScratchOffsetAlignment);
  scratch_slice_ = AlignUp(std::max(sizes.buildScratchSize, sizes.updateScratchSize), slice_alignment);
  scratch_ = gpu.CreateBuffer(scratch_slice_ * count, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kDeviceLocal);
  gpu.Name(VK_OBJECT_TYPE_BUFFER, scratch_.buffer, "crowd scratch");
  for (uint32_t i = 0; i < count; ++i) {
    const std::string name = "crowd " + std::to_string(i) + " (blob copy, refit)";
    structures_.push_back(gpu.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                          sizes.accelerationStructureSize, name.c_str()));
  }
}

CrowdBlases::~CrowdBlases() {
  for (AccelerationStructure& as : structures_) gpu_.Destroy(as);
  gpu_.Destroy(scratch_);
}

void CrowdBlases::RecordBuilds(VkCommandBuffer cb, uint32_t parity, VkBuildAccelerationStructureModeKHR mode) const {
  if (structures_.empty()) return;
  const bool update = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  const BuildInput blob = deforming_.BlobInput(parity);
  for (uint32_t i = 0; i < count(); ++i) {
    const VkAccelerationStructureKHR as = structures_[i].handle;
    // Distinct storage and scratch slices: no barrier is needed between these builds.
    RecordBuild(gpu_, cb, {blob.Info(mode, update ? as : VK_NULL_HANDLE, as, scratch_.address + scratch_slice_ * i)},
                {&blob});
  }
}

}  // namespace scene
