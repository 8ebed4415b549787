#pragma once
// What a hook does with a call its validation said to skip (setting `protect`; layer/report/protect_scope.h). A skip
// the app's callback asked for (VK_TRUE) is only a skip; one protect mode caused is withheld: a recorded command
// marks its command buffer, so that no submission of it runs, and every withheld call is counted and named once.
// HaltSubmissionsAfter is protect mode for errors judged at completion, when the work already ran.
#include "layer_data.h"
#include "protect_marks.h"
#include "protect_notices.h"
#include "protect_scope.h"

namespace asval::hooks {

// A recorded command that is not passed down.
inline void WithholdRecordedCommand(DeviceData& data, const char* function, VkCommandBuffer cb,
                                    const ProtectScope& protect) {
  if (!protect.withheld()) return;
  const bool marked = RecordWithheldCommand(data.state, cb, function, protect.vuid(), protect.where());
  ReportWithheldCommand(MakeCheckContext(data), function, cb, protect, marked);
}

// A host command that does not run: VK_ERROR_VALIDATION_FAILED_EXT, what the Khronos layer returns for a skip.
inline VkResult WithholdHostCommand(DeviceData& data, const char* function, VkDevice device,
                                    const ProtectScope& protect) {
  if (protect.withheld()) {
    RecordWithheldHostCommand(data.state);
    ReportWithheldHostCommand(MakeCheckContext(data), function, device, protect);
  }
  return VK_ERROR_VALIDATION_FAILED_EXT;
}

// Protect mode, before a submission is applied: true when it must be withheld whole, because submissions are halted
// (HaltSubmissionsAfter) or a submitted command buffer holds a command the layer withheld (the first is named).
// for_each_command_buffer(visit) calls visit(cb, location) for every submitted command buffer, in order.
template <typename ForEachCommandBuffer>
bool WithholdSubmission(DeviceData& data, const char* function, VkQueue queue,
                        ForEachCommandBuffer&& for_each_command_buffer) {
  if (const std::shared_ptr<const WithheldCommand> halt = data.state.protect_halt.Cause()) {
    RecordWithheldSubmission(data.state);
    ReportHaltedSubmission(MakeCheckContext(data), function, queue, *halt);
    return true;
  }
  bool withheld = false;
  for_each_command_buffer([&](VkCommandBuffer cb, const Location& loc) {
    if (withheld) return;
    if (const std::shared_ptr<const WithheldCommand> command = data.state.command_buffers.Withheld(cb)) {
      withheld = true;
      RecordWithheldSubmission(data.state);
      ReportWithheldSubmission(MakeCheckContext(data), loc, queue, cb, *command);
    }
  });
  return withheld;
}

// Errors judged at completion (execution-time capture) while `protect` was open: the work already ran, so every
// later submission on the device is withheld (named once here, and in each submission's notice).
// `deferred`: errors of a batch judged when its semaphore wait was signaled, after it went down (ordered_batches.h).
inline void HaltSubmissionsAfter(DeviceData& data, const ProtectScope& protect, bool deferred = false) {
  if (!protect.withheld() || data.state.protect_halt.Cause()) return;
  RecordSubmissionHalt(data.state, protect.function(), protect.vuid(), protect.where());
  ReportSubmissionHalt(MakeCheckContext(data), data.device, protect, deferred);
}

}  // namespace asval::hooks
