#pragma once
// The host commands of VK_KHR_acceleration_structure, executed by the device below: the host inputs are copied
// into staging buffers, the command is recorded as its device twin, submitted and waited for, and results are
// copied back to the host addresses. Each returns what the command returns.
#include <vulkan/vulkan.h>

namespace asval_test_driver {

struct DeviceData;

VkResult BuildOnHost(DeviceData& device, uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                     const VkAccelerationStructureBuildRangeInfoKHR* const* ranges);
VkResult CopyOnHost(DeviceData& device, const VkCopyAccelerationStructureInfoKHR& info);
VkResult CopyToMemoryOnHost(DeviceData& device, const VkCopyAccelerationStructureToMemoryInfoKHR& info);
VkResult CopyFromMemoryOnHost(DeviceData& device, const VkCopyMemoryToAccelerationStructureInfoKHR& info);
VkResult WritePropertiesOnHost(DeviceData& device, uint32_t count, const VkAccelerationStructureKHR* structures,
                               VkQueryType type, size_t data_size, void* data, size_t stride);

}  // namespace asval_test_driver
