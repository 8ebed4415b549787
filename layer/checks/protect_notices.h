#pragma once
// Protect mode's notices (setting `protect`, layer/report/protect_scope.h): each call the layer kept from the
// driver, named once with the finding that made it do so, and the counts at vkDestroyDevice. They are information
// messages that report_flags and the duplicate limit do not hide (Reporter::ReportLayerAction): a CI run whose app
// failed after a withheld call must be able to see why.
#include <vulkan/vulkan.h>

#include "check_context.h"
#include "protect_marks.h"
#include "protect_scope.h"

namespace asval {

// The id of every notice of a withheld call.
inline constexpr const char kProtectWithheldId[] = "ASVAL-Protect-Withheld";

// A recorded command not passed down. `marked`: its command buffer is marked (false: the layer never saw it
// allocated, so its submissions cannot be withheld; said in the notice).
void ReportWithheldCommand(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                           const ProtectScope& cause, bool marked);
// A host command (build, copy, property write) that returned VK_ERROR_VALIDATION_FAILED_EXT without running.
void ReportWithheldHostCommand(const CheckContext& ctx, const char* function, VkDevice device,
                               const ProtectScope& cause);
// A destroy or free not passed down now because the device still uses the object (family lifetime): the layer
// makes it once that work completed.
void ReportDeferredDestroy(const CheckContext& ctx, const char* function, VkDevice device, const ProtectScope& cause);
// A submission not passed down because the command buffer at `cb_loc` holds a withheld command.
void ReportWithheldSubmission(const CheckContext& ctx, const Location& cb_loc, VkQueue queue, VkCommandBuffer cb,
                              const WithheldCommand& command);
// A submission not passed down because of an error found when it was submitted (in execution order).
void ReportWithheldSubmission(const CheckContext& ctx, const char* function, VkQueue queue,
                              const ProtectScope& cause);
// An error judged at completion (execution-time capture) halted submissions: every later one is withheld.
// `deferred`: found when a batch deferred until its semaphore wait was signaled was judged (submission_order.h).
void ReportSubmissionHalt(const CheckContext& ctx, VkDevice device, const ProtectScope& cause, bool deferred = false);
// A submission not passed down because submissions are halted (SubmissionHalt, protect_marks.h).
void ReportHaltedSubmission(const CheckContext& ctx, const char* function, VkQueue queue,
                            const WithheldCommand& cause);
// ASVAL-History-Summary's protect line at vkDestroyDevice; none when nothing was withheld.
void ReportProtectSummary(const DeviceState& state, Reporter& reporter, VkDevice device);

}  // namespace asval
