#pragma once
// A top-level build's instance references, judged when the submission that ran the build completes, on the
// instances the device really read (execution-time capture, layer/capture) against the structures alive when it
// was submitted:
//   pInfos-06707                     each reference is 0 or the device address of a live structure
//   pInfos-03709                     the buffer each referenced structure was created on is bound to memory
//   None-03407                       no reference names another info's destination in the same command
//   dstAccelerationStructure-03706   no referenced structure's memory overlaps the bytes the command writes for
//                                    another info's destination
//   pInfos-03717                     arrays of instance pointers: each pointer is 16-byte aligned (the records
//                                    they point to, gathered by the layer's dispatch, are judged by the rules above
//                                    as a plain array's; where they are not gathered: skipped, counted)
// Const: reports only; run under the device's capture processing lock.
#include "build_activity.h"
#include "check_context.h"

namespace asval {

// Returns whether every instance's reference could be judged and named a live bottom-level structure (or was 0);
// then `referenced` (may be null) holds each distinct structure referenced, with its serial (family traces).
bool CheckInstanceReferences(const CheckContext& ctx, const InstanceReferenceCheck& build,
                             ReferencedStructures* referenced = nullptr);

}  // namespace asval
