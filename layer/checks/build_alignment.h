#pragma once
// Alignment rules of the acceleration-structure build commands (family "alignment").
#include "build_command.h"
#include "check_context.h"
#include "resolved_build.h"

namespace asval {

// VUID-vkCmdBuildAccelerationStructures{,Indirect}KHR-pInfos-03710: each pInfos[i].scratchData.deviceAddress
// is a multiple of minAccelerationStructureScratchOffsetAlignment (device builds only: host scratch is a
// host pointer).
// Then the alignment of the geometry inputs and of the indirect arrays (build_input_alignment.h).
bool ValidateBuildAlignment(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);

}  // namespace asval
