#pragma once
// VK_NV_ray_tracing's acceleration-structure commands: the rules their arguments and the shadow state decide when
// the command is recorded. Each family is asked of the settings as for the KHR commands; each function returns true
// when a callback asked that the call not be passed down. (The rules on what executed before, update-02490,
// src-04963, src-03411, pAccelerationStructures-04958 and 06215, are judged at submission: update_rules.h.)
//   vkCmdBuildAccelerationStructureNV:
//     structure  geometryCount-02241 (maxGeometryCount), dst-02488 (dst's creation info holds the build)
//     handles    update-02489 (src given), dst-07787 (dst bound to memory)
//     addresses  update-02491 / update-02492 (scratch size), scratch-03522 / instanceData-03523 (RAY_TRACING usage)
//     aliasing   update-03526 (an update's src and dst are one object or do not alias)
//   vkCmdCopyAccelerationStructureNV (copies): mode-03410, dst-07791 (no overlap), dst-07792 (dst bound)
//   vkCmdWriteAccelerationStructuresPropertiesNV (copies): queryType-06216, queryPool-03755,
//     accelerationStructure-03757 (each structure bound)
#include <vulkan/vulkan.h>

#include "check_context.h"

namespace asval {

struct NvBuildArgs {
  const VkAccelerationStructureInfoNV* info = nullptr;
  VkBuffer instance_data = VK_NULL_HANDLE;
  VkBool32 update = VK_FALSE;
  VkAccelerationStructureNV dst = VK_NULL_HANDLE;
  VkAccelerationStructureNV src = VK_NULL_HANDLE;
  VkBuffer scratch = VK_NULL_HANDLE;
  VkDeviceSize scratch_offset = 0;
};

bool ValidateBuildNV(const CheckContext& ctx, VkCommandBuffer cb, const NvBuildArgs& args);
bool ValidateCopyNV(const CheckContext& ctx, VkCommandBuffer cb, VkAccelerationStructureNV dst,
                    VkAccelerationStructureNV src, VkCopyAccelerationStructureModeKHR mode);
bool ValidateWritePropertiesNV(const CheckContext& ctx, VkCommandBuffer cb, uint32_t count,
                               const VkAccelerationStructureNV* structures, VkQueryType type, VkQueryPool pool);

}  // namespace asval
