#pragma once
// Family "traces" (issue 29): the top-level structures that trace and ray-query work reads are built, in execution
// order. At submission each vkCmdTraceRays*, vkCmdDispatch* and vkCmdDraw* whose bound pipeline statically uses
// structure descriptors (shader_structure_use.h) is judged, just before it executes in the submission's order: every
// structure in those descriptors (the set bound at that set number when the command was recorded, read as it is at
// submission; or the structures pushed there; or the descriptor-buffer bytes bound there, read at submission) must
// have had a build execute on it, and that build must have made a top-level structure
// (VUID-RuntimeSpirv-OpTraceRayKHR-06359 for pipelines that trace, VUID-RuntimeSpirv-OpRayQueryInitializeKHR-06352
// for ray queries).
//
// Not judged, counted by reason (TracedSkip; the summary at vkDestroyDevice): nothing bound or written there,
// descriptors the layer cannot read (push templates, unmapped descriptor buffers, writes past a binding's end), a
// structure the layer did not know when written or destroyed since (a handle is not an identity), unknown histories.
// Structures a shader reaches from an address (OpConvertUToAccelerationStructureKHR) cannot be seen: nothing is
// judged or counted for them. Draws are judged like dispatches (ray queries in graphics and mesh pipelines).
#include "device_state.h"
#include "history_findings.h"
#include "update_rules.h"

namespace asval {

enum class TracedSkip : uint8_t {
  kNotBound,           // no set bound (or pushed) at that set number
  kNotWritten,         // the set's binding holds no structure the layer saw written
  kUnreadable,         // descriptors the layer does not read (templates pushed, unmapped descriptor buffers, ...)
  kUnknownStructure,   // a structure the layer did not know when it was written
  kDestroyed,          // destroyed since it was written (its descriptor is stale)
  kUnknownHistory,     // the structure's history is unknown
  kReferencesUnknown,  // what its last build's instances referenced is not known (not captured, or not completed yet)
  kBottomLevelUnknown,  // a referenced bottom level whose storage or history cannot be judged (counted per walk)
  kCount
};
const char* TracedSkipName(TracedSkip skip);

// Layer-specific (the chapter's "Those bottom level acceleration structure objects must be valid when the top level
// acceleration structure is accessed" has no VUID): a traced top level's last build referenced a bottom-level
// structure that was destroyed since, or whose storage's memory was freed since.
inline constexpr const char kBottomLevelInvalidId[] = "ASVAL-Traces-BottomLevelInvalid";
// Layer-specific warning: a traced top level's last build referenced a bottom-level structure rebuilt since with
// another geometry layout (count or types), and the top level was not built or updated after: the result is not
// defined (the top level's instance data describe the old structure), not invalid.
inline constexpr const char kBottomLevelChangedId[] = "ASVAL-Traces-BottomLevelChanged";

// Judges one kTrace operation against the histories before it. Call with the store's lock held.
void CheckTracedStructures(const DeviceState& state, const HistoryStore& store, const OpBatch& batch, const AsOp& op,
                           const HistoryCheckSite& site, HistoryFindings& out);

inline constexpr const char kTracesSummaryId[] = "ASVAL-Traces-Summary";
// vkDestroyDevice: how many traced structures were judged, and why others were not (info; in the JSON report).
void ReportTracesSummary(const DeviceState& state, Reporter& reporter, VkDevice device);

}  // namespace asval
