// What the two build recorders share (capture_recording.h).
#include "capture_recording.h"

#include <algorithm>
#include <atomic>

#include "capture_reduce_jobs.h"
#include "capture_run_end.h"

namespace asval {
namespace recording {

void KeepOpen(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
              std::size_t copies_before) {
  CaptureRun& run = recording.capture_run;
  if (copies_before == 0 && !run.copies.empty()) run.aliases_epoch = ctx.aliases.Epoch();
  if (run.Empty() || run.IsOpen()) return;
  run.Open(ctx.state.command_buffers.open_capture_runs());
  // Primaries only: the Khronos layer (1.3.239) takes a wait on an event set earlier in the same secondary for one
  // on an event never set (VUID-vkCmdWaitEvents-srcStageMask-parameter, "instead is 0x0"); a secondary's capture
  // point waits with a barrier.
  const bool events = recording.level == VK_COMMAND_BUFFER_LEVEL_PRIMARY && !recording.simultaneous_use;
  if (cb != VK_NULL_HANDLE && events && recording.capture_log) {
    run.start_event = recording.capture_log->TakeEvent();
    // Signaled once everything recorded before the run has executed (the stage mask its wait names too).
    if (run.start_event != VK_NULL_HANDLE) ctx.next.CmdSetEvent(cb, run.start_event, kRunStartStages);
  }
}

bool Reserve(const CaptureContext& ctx, CaptureLog& log, VkDeviceSize size, CapturedBytes* where) {
  if (log.Reserve(size, where)) return true;
  ctx.counters.failures.capture_memory_failures.fetch_add(1, std::memory_order_relaxed);
  return false;
}

bool CaptureDropped(const CaptureContext& ctx, uint64_t needing, std::vector<uint32_t>& captured) {
  captured.clear();
  FailureCounters& failures = ctx.counters.failures;
  failures.allocation_failures.fetch_add(1, std::memory_order_relaxed);
  failures.capture_commands_dropped.fetch_add(1, std::memory_order_relaxed);
  ctx.counters.NotCaptured(CaptureSkip::kAllocationFailed, needing);
  return false;
}

bool RoomForJobs(const CaptureContext& ctx, CaptureRun& run, CaptureLog& log, uint32_t jobs) {
  JobBlock& block = run.block;
  const VkPipeline pipeline = ctx.pool.ReducePipeline();
  if (pipeline == VK_NULL_HANDLE && !ctx.counters.failures.reduce_pipeline_failed.exchange(true)) {
    ctx.counters.failures.inserted_failures.fetch_add(1, std::memory_order_relaxed);  // once: made once
  }
  if (block.Room() >= jobs && block.dispatch.pipeline == pipeline) return true;
  if (block.dispatch.jobs != 0) run.dispatches.push_back(block.dispatch);
  return AcquireJobs(block, log, jobs, std::max<uint32_t>(64, 2 * block.capacity), pipeline);
}

}  // namespace recording
}  // namespace asval
