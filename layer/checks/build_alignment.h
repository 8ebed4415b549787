#pragma once
// Alignment rules of the acceleration-structure build commands.
#include <vulkan/vulkan.h>

#include "check_context.h"

namespace asval {

// VUID-vkCmdBuildAccelerationStructures{,Indirect}KHR-pInfos-03710: each pInfos[i].scratchData.deviceAddress
// must be a multiple of minAccelerationStructureScratchOffsetAlignment. vuid names the command's own rule.
bool ValidateScratchAlignment(const CheckContext& ctx, const Location& loc, VkCommandBuffer command_buffer,
                              uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                              const char* vuid);

}  // namespace asval
