#pragma once
// An indirect build's range infos, read by the device from pIndirectDeviceAddresses when it executed
// (execution-time capture): each primitiveCount must not exceed the ppMaxPrimitiveCounts[i][j] the command was
// recorded with (ppMaxPrimitiveCounts-03653). Judged when the submission completes. Const: reports only; run under
// the device's capture processing lock.
#include "build_activity.h"
#include "check_context.h"

namespace asval {

void CheckIndirectRanges(const CheckContext& ctx, const IndirectRangeCheck& build);

}  // namespace asval
