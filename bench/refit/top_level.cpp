#include "top_level.h"

#include <algorithm>
#include <cmath>

#include "device_buffers.h"

namespace refit {

TopLevel::TopLevel(vkkit::Device& device, const std::vector<VkDeviceAddress>& bottom_levels) : device_(device) {
  const uint32_t count = static_cast<uint32_t>(bottom_levels.size());
  instances_ = device.CreateBuffer(count * sizeof(VkAccelerationStructureInstanceKHR),
                                   VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  auto* instances = static_cast<VkAccelerationStructureInstanceKHR*>(instances_.mapped);
  const uint32_t columns = static_cast<uint32_t>(std::ceil(std::sqrt(static_cast<double>(count))));
  for (uint32_t i = 0; i < count; ++i) {
    VkAccelerationStructureInstanceKHR& instance = instances[i];
    instance = VkAccelerationStructureInstanceKHR{};
    // Identity rotation, a translation on a grid of unit cells (each mesh spans the unit square).
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    instance.transform.matrix[0][3] = 1.25f * static_cast<float>(i % columns);
    instance.transform.matrix[1][3] = 1.25f * static_cast<float>(i / columns);
    instance.instanceCustomIndex = i;
    instance.mask = 0xff;
    instance.accelerationStructureReference = bottom_levels[i];
  }

  geometry_.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
  geometry_.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  geometry_.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  geometry_.geometry.instances.data.deviceAddress = instances_.address;
  info_.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
  info_.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  info_.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
                VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  info_.geometryCount = 1;
  info_.pGeometries = &geometry_;
  range_.primitiveCount = count;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                               &info_, &count, &sizes);
  storage_ = CreateDeviceLocalBuffer(device, sizes.accelerationStructureSize,
                                     VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  scratch_ = CreateDeviceLocalBuffer(device, std::max(sizes.buildScratchSize, sizes.updateScratchSize),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  create.buffer = storage_.buffer;
  create.size = sizes.accelerationStructureSize;
  create.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &create, nullptr, &structure_),
               "vkCreateAccelerationStructureKHR");
  info_.dstAccelerationStructure = structure_;
  info_.scratchData.deviceAddress = scratch_.address;
}

TopLevel::~TopLevel() {
  device_.DestroyAccelerationStructureKHR(device_.handle(), structure_, nullptr);
  device_.Destroy(scratch_);
  device_.Destroy(storage_);
  device_.Destroy(instances_);
}

void TopLevel::Record(VkCommandBuffer cb, VkBuildAccelerationStructureModeKHR mode) {
  info_.mode = mode;
  info_.srcAccelerationStructure = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? structure_ : VK_NULL_HANDLE;
  const VkAccelerationStructureBuildRangeInfoKHR* range = &range_;
  device_.CmdBuildAccelerationStructuresKHR(cb, 1, &info_, &range);
}

}  // namespace refit
