#pragma once
// A top-level build's instance references (pInfos-06707: each accelerationStructureReference is 0 or the device
// address of a valid acceleration structure), judged when the submission that ran the build completes, on the
// instances the device really read (execution-time capture, layer/capture) against the structures alive when it
// was submitted. Const: reports only; run under the device's capture processing lock.
#include "build_activity.h"
#include "check_context.h"

namespace asval {

void CheckInstanceReferences(const CheckContext& ctx, const InstanceReferenceCheck& build);

}  // namespace asval
