#include "protect_notices.h"

#include <fmt/format.h>

#include <string>

#include "history_findings.h"

namespace asval {

namespace {

// "VUID-... (vkCmd...(): pInfos[0].mode)", or a plain statement when the finding's text could not be kept.
std::string Cause(const std::string& vuid, const std::string& where) {
  if (vuid.empty()) return "an error (its name could not be kept: the layer's allocation failed)";
  return fmt::format("{} ({})", vuid, where);
}

// What every withheld submission's notice says happened to it (the text goes on after it).
constexpr const char kSubmissionNotPassedDown[] =
    "the submission's command buffers were not passed down and it returned VK_ERROR_VALIDATION_FAILED_EXT (none of "
    "them ran; its batches went down empty, with their semaphore waits and signals and its fence, so that what waits "
    "for it still completes";

}  // namespace

void ReportWithheldCommand(const CheckContext& ctx, const char* function, VkCommandBuffer cb,
                           const ProtectScope& cause, bool marked) {
  const std::string then =
      marked ? "The command buffer is marked: every submission of it is withheld (VK_ERROR_VALIDATION_FAILED_EXT) "
               "until it is reset or begun again, since what it records next may depend on this command."
             : "The layer never saw this command buffer allocated, so it cannot withhold its submissions.";
  ctx.reporter.ReportLayerAction(
      kProtectWithheldId, Location(function), {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, cb)},
      fmt::format("protect: this command was not passed down (not recorded) because asval reported {}. {}",
                  Cause(cause.vuid(), cause.where()), then));
}

void ReportWithheldHostCommand(const CheckContext& ctx, const char* function, VkDevice device,
                               const ProtectScope& cause) {
  ctx.reporter.ReportLayerAction(
      kProtectWithheldId, Location(function), {Obj(VK_OBJECT_TYPE_DEVICE, device)},
      fmt::format("protect: this command was not passed down (it did not run) and returned "
                  "VK_ERROR_VALIDATION_FAILED_EXT because asval reported {}.",
                  Cause(cause.vuid(), cause.where())));
}

void ReportDeferredDestroy(const CheckContext& ctx, const char* function, VkDevice device, const ProtectScope& cause) {
  ctx.reporter.ReportLayerAction(
      kProtectWithheldId, Location(function), {Obj(VK_OBJECT_TYPE_DEVICE, device)},
      fmt::format("protect: this call was not passed down now because asval reported {}; the layer makes it once the "
                  "work that uses the object completed (at the latest at vkDestroyDevice), so that the device never "
                  "reads or writes freed memory and nothing leaks.",
                  Cause(cause.vuid(), cause.where())));
}

void ReportWithheldSubmission(const CheckContext& ctx, const Location& cb_loc, VkQueue queue, VkCommandBuffer cb,
                              const WithheldCommand& command) {
  ctx.reporter.ReportLayerAction(
      kProtectWithheldId, cb_loc, {Obj(VK_OBJECT_TYPE_QUEUE, queue), Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, cb)},
      fmt::format("lacks a command asval withheld when it was recorded ({}, for {}). protect: {}).", command.function,
                  Cause(command.vuid, command.where), kSubmissionNotPassedDown));
}

void ReportWithheldSubmission(const CheckContext& ctx, const char* function, VkQueue queue,
                              const ProtectScope& cause) {
  ctx.reporter.ReportLayerAction(
      kProtectWithheldId, Location(function), {Obj(VK_OBJECT_TYPE_QUEUE, queue)},
      fmt::format("protect: {}; the build history is as before it) because asval reported {} in execution order.",
                  kSubmissionNotPassedDown, Cause(cause.vuid(), cause.where())));
}

void ReportSubmissionHalt(const CheckContext& ctx, VkDevice device, const ProtectScope& cause, bool deferred) {
  if (deferred) {
    ctx.reporter.ReportLayerAction(
        kProtectWithheldId, Location(cause.function()), {Obj(VK_OBJECT_TYPE_DEVICE, device)},
        fmt::format("protect: asval reported {} when it judged a batch that waited for a timeline semaphore value "
                    "signaled only later (execution order across queues): that batch had been passed down when it "
                    "was submitted, and what it builds may be corrupt. Every later submission on this device is "
                    "withheld (VK_ERROR_VALIDATION_FAILED_EXT), so that nothing uses it.",
                    Cause(cause.vuid(), cause.where())));
    return;
  }
  ctx.reporter.ReportLayerAction(
      kProtectWithheldId, Location(cause.function()), {Obj(VK_OBJECT_TYPE_DEVICE, device)},
      fmt::format("protect: asval reported {} when the work that broke the rule completed (execution-time "
                  "capture): that work already ran, and what it built may be corrupt. Every later submission on this "
                  "device is withheld (VK_ERROR_VALIDATION_FAILED_EXT), so that nothing uses it.",
                  Cause(cause.vuid(), cause.where())));
}

void ReportHaltedSubmission(const CheckContext& ctx, const char* function, VkQueue queue,
                            const WithheldCommand& cause) {
  ctx.reporter.ReportLayerAction(
      kProtectWithheldId, Location(function), {Obj(VK_OBJECT_TYPE_QUEUE, queue)},
      fmt::format("protect: {}) because an earlier submission broke a rule found when it completed: {}. Every "
                  "submission on this device since is withheld.",
                  kSubmissionNotPassedDown, Cause(cause.vuid, cause.where)));
}

void ReportProtectSummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  const ProtectCounters& c = state.protect_counters;
  const uint64_t commands = c.commands_withheld.load(std::memory_order_relaxed);
  const uint64_t submissions = c.submissions_withheld.load(std::memory_order_relaxed);
  const uint64_t host = c.host_commands_withheld.load(std::memory_order_relaxed);
  const uint64_t lost = c.synchronizations_lost.load(std::memory_order_relaxed);
  const bool halted = state.protect_halt.Cause() != nullptr;
  if (commands == 0 && submissions == 0 && host == 0 && !halted) return;
  reporter.ReportLayerAction(
      kHistorySummaryId, Location("vkDestroyDevice"), {Obj(VK_OBJECT_TYPE_DEVICE, device)},
      fmt::format("Protect mode kept from the driver: recorded_commands_withheld={} submissions_withheld={} "
                  "host_commands_withheld={} submissions_halted_by_completion_error={} (each named in an {} message).{}",
                  commands, submissions, host, halted ? 1 : 0, kProtectWithheldId,
                  lost == 0 ? ""
                            : fmt::format(" The layer could not allocate the empty batches of {} withheld submissions: "
                                          "their fences and semaphores were not signaled.",
                                          lost)));
}

}  // namespace asval
