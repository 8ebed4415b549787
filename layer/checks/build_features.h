#pragma once
// Features and modes of the acceleration-structure build commands (family "features"):
//   accelerationStructure-08923            vkCmdBuildAccelerationStructuresKHR needs the accelerationStructure feature
//   accelerationStructureIndirectBuild-03650  the indirect command needs accelerationStructureIndirectBuild
//   accelerationStructureHostCommands-03581   vkBuildAccelerationStructuresKHR needs accelerationStructureHostCommands
//   commandBuffer-09547                    device builds: the command buffer is not a protected one
//   mode-04628                             each pInfos[i].mode is a VkBuildAccelerationStructureModeKHR value
//   pInfos-04630                           UPDATE needs a srcAccelerationStructure
#include "build_command.h"
#include "check_context.h"

namespace asval {

bool ValidateBuildFeatures(const CheckContext& ctx, const BuildCommand& cmd);

}  // namespace asval
