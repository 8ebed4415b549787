#pragma once
// Handles and types of the acceleration-structure build commands (family "handles"):
//   srcAccelerationStructure-04629   a non-null srcAccelerationStructure is a live structure of this device
//   dstAccelerationStructure-03800   dstAccelerationStructure is a live structure of this device
//   pInfos-03699 / 03700             a top-level (bottom-level) build writes a structure created top-level
//                                    (bottom-level) or generic
//   dstAccelerationStructure-03698   no two infos share a destination
//   pInfos-03403                     no info's source is another info's destination
//   pInfos-03707 / 03708             device builds: the buffer behind the destination (and, for updates, the
//                                    source) is bound to memory
//   VkAccelerationStructureBuildGeometryInfoKHR-flags-04928 / dstAccelerationStructure-04927
//                                    a motion build (BUILD_MOTION_BIT_NV) writes a structure created for motion
//                                    (CREATE_MOTION_BIT_NV), and only such a build writes one
// The duplicate rules sort the handles (O(n log n)) in a per-thread buffer that is reused, so a steady
// stream of many-info calls allocates nothing.
#include "build_command.h"
#include "check_context.h"
#include "resolved_build.h"

namespace asval {

// The records of each info's structures come from the command's resolved view.
bool ValidateBuildHandles(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);

}  // namespace asval
