#pragma once
// An indirect build's range infos, read by the device from pIndirectDeviceAddresses when it executed
// (execution-time capture): each primitiveCount must not exceed the ppMaxPrimitiveCounts[i][j] the command was
// recorded with (ppMaxPrimitiveCounts-03653), and, for an update, must be the primitiveCount its source was last
// built with (primitiveCount-03769; the source's build as the history held it when the update was submitted);
// each must be a valid VkAccelerationStructureBuildRangeInfoKHR for its geometry by the range rules the direct
// command is held to at record time (pIndirectDeviceAddresses-03651, build_ranges.h; family "structure").
// Judged when the submission completes; what cannot be judged (bytes the layer cannot vouch for, a source count
// that stayed on the device) is skipped and counted. Const: reports only; run under the device's capture
// processing lock.
#include "build_activity.h"
#include "check_context.h"

namespace asval {

void CheckIndirectRanges(const CheckContext& ctx, const IndirectRangeCheck& build);

}  // namespace asval
