#pragma once
// One pass over a build command for the two families that place its bytes in memory: "addresses"
// (build_addresses.h, build_sizes.h) and "aliasing" (build_aliasing.h). Both read each info's sizes, destination
// and scratch from the command's resolved view (resolved_build.h), looked up once per call. Either family can
// still be switched off alone.
#include "build_command.h"
#include "check_context.h"
#include "resolved_build.h"

namespace asval {

// The families' entry in the build-family table: runs whichever of the two the settings enable.
inline constexpr LayerSettingFlagBits kCheckAddressesOrAliasing =
    static_cast<LayerSettingFlagBits>(kCheckAddresses | kCheckAliasing);
bool ValidateBuildMemory(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);

}  // namespace asval
