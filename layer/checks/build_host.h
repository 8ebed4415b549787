#pragma once
// Rules of vkBuildAccelerationStructuresKHR alone (family "host"):
//   pInfos-03722 / 03723 / 03724   the destination, an update's source, and every structure an instance
//                                  references are on buffers bound to host-visible memory
//   pInfos-03775 / 03776 / 03777   ... to memory not allocated with multiple instances
//   pInfos-03725 / 03726           scratchData.hostAddress is not null when the build (update) scratch size the
//                                  driver reports for this build is not 0, and, when it points into memory the
//                                  app mapped (vkMapMemory), that size fits before the mapping ends (elsewhere,
//                                  how much valid memory is behind a pointer cannot be known)
//   pInfos-03771 / 03772 / 03774 / 03778   vertex, index, AABB and instance host addresses are not null for a
//                                  geometry that builds primitives
//   pInfos-03779                   each non-zero instance reference is a live acceleration structure
//   deferredOperation-03678        the deferred operation has no earlier host command still running
#include "build_command.h"
#include "check_context.h"
#include "resolved_build.h"

namespace asval {

bool ValidateBuildHost(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);

}  // namespace asval
