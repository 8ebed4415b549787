#pragma once
// The history family: rules that compare an operation with what was executed before it on the same structure.
//   updates:  pInfos-03667 (source built with ALLOW_UPDATE), 03758 (geometryCount), 03759 (flags), 03760 (type),
//             03761..03767 (per geometry: type, flags, vertexFormat, maxVertex, indexType, transform null-ness),
//             primitiveCount-03769; for all three build commands
//   copies:   VkCopyAccelerationStructureInfoKHR-src-04963 (source constructed), src-03411 (compaction needs
//             ALLOW_COMPACTION); VkCopyAccelerationStructureToMemoryInfoKHR-src-04959
//   queries:  vk{Cmd,}WriteAccelerationStructuresPropertiesKHR pAccelerationStructures-04964 (built),
//             accelerationStructures-03431 (compacted size needs ALLOW_COMPACTION)
//   aliasing: ASVAL-History-Clobbered (warning): a source whose memory another operation wrote since it was built
// and, in the copies family (it needs the history's serialization size),
//             VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561.
// Device commands are checked when submitted (submit_checks.h), host commands when called. A structure whose
// history is unknown is skipped, and the skip counted; never guessed.
#include <vulkan/vulkan.h>

#include "device_state.h"
#include "history_findings.h"

namespace asval {

// Where an operation is being checked.
struct HistoryCheckSite {
  Location loc;                                    // e.g. vkQueueSubmit(): pSubmits[0].pCommandBuffers[1]
  VkCommandBuffer submitted = VK_NULL_HANDLE;      // the command buffer submitted (null for host calls)
  bool describe_origin = false;                    // prefix messages with where the operation was recorded
  uint64_t submission = 0;                         // SubmissionCaptures::id of the submission (0: host calls)
  // DeviceState ids below this one were given before the app's submitting call (a deferred batch is applied later
  // than its call): what was destroyed after it does not make the command buffer invalid at submission.
  uint64_t submitted_at = 0;
};

// Checks `op` against the histories as they are before it executes. Call with the store's lock held.
void CheckOpHistory(const DeviceState& state, const HistoryStore& store, uint32_t enabled_checks,
                    const OpBatch& batch, const AsOp& op, const HistoryCheckSite& site, HistoryFindings& out);

}  // namespace asval
