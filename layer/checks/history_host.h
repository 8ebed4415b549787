#pragma once
// The history rules where they are checked outside a submission (layer/checks: const, they only report):
//   host commands:  checked against the histories when called (device commands: at submission, submit_checks.h);
//   the summary:    an info message at vkDestroyDevice counting the checks skipped for unknown history.
#include <vulkan/vulkan.h>

#include "build_command.h"
#include "check_context.h"

namespace asval {

// The history family's line in the build-family table: host builds are checked when called (device builds
// when submitted, so this does nothing for them).
bool ValidateBuildHistory(const CheckContext& ctx, const BuildCommand& cmd);
// Checks host operations (history_recorder.h builds them) against the histories now; reports. True when a
// callback asked to skip the call.
bool ValidateHostOps(const CheckContext& ctx, const OpBatch& batch, const char* function);
// vkDestroyDevice: info messages (and JSON lines) counting the history checks skipped for unknown history, what the
// capture could not capture, and the layer's own failures (allocations, capture memory, its own Vulkan objects:
// failure_counters.h) with what they made unknown.
void ReportHistorySummary(const DeviceState& state, Reporter& reporter, VkDevice device);

}  // namespace asval
