#pragma once
// Family "lifetime" (issue 29), at submission: a command buffer is invalid once a structure or buffer one of its
// acceleration-structure commands recorded was destroyed (the command buffer lifecycle: "deleting a resource that
// was used in a command recorded to a command buffer"), and submitting it breaks
// VUID-vkQueueSubmit-pCommandBuffers-00070 / VUID-vkQueueSubmit2-commandBuffer-03874. A secondary's commands count
// for the primary that executes them (both are invalid).
//
// Recorded objects: the structures a command names by handle (source and destination of builds, updates, copies,
// serializations and deserializations, the structures a property query reads), and the buffers holding the addresses
// it reads or writes (scratch, geometry inputs, instances, serialized bytes; OpBatch::touches). Handles and addresses
// are reused, so each is judged by serials (OpOrigin::recorded_at against ObjectLifetimes): reported only when the
// structure that lived under the handle when the command was recorded, or every buffer bound then holding the
// address, was destroyed after the recording. A handle or address that named nothing then is another rule's.
// Destroys older than the layer's memory of them (ObjectLifetimes' ring) are skipped and counted
// (recorded_forgotten in ASVAL-Lifetime-Summary). Trace and dispatch bindings are not judged here (family traces
// counts a destroyed binding).
//
// Cost: while nothing was destroyed after a command was recorded, two loads per operation.
#include "device_state.h"
#include "history_findings.h"
#include "update_rules.h"

namespace asval {

// Judges the objects one submitted operation recorded. Call with the history store's lock held (findings are
// reported after it is released).
void CheckRecordedObjects(const DeviceState& state, const OpBatch& batch, const AsOp& op, const HistoryCheckSite& site,
                          HistoryFindings& out);

}  // namespace asval
