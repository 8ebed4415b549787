#pragma once
// The sizes the driver reports for one info of a build command, and the rules that compare with them
// (family "addresses"):
//   pInfos-10126 (older: 03675)   direct and host builds: dstAccelerationStructure was created at least as
//                                 large as accelerationStructureSize for this geometry and these counts
//   pInfos-03652                  indirect builds: the same, with ppMaxPrimitiveCounts[i] as the counts
//   pInfos-03801                  an instance geometry's count is at most maxInstanceCount
// The scratch rules that use the same sizes are in build_addresses.h.
#include "build_command.h"
#include "build_size_lookup.h"
#include "check_context.h"
#include "resolved_build.h"

namespace asval {

// pInfos-10126 / pInfos-03652 and pInfos-03801 for pInfos[i], all three commands.
bool ValidateInfoSizes(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r);

}  // namespace asval
