// What the two build recorders share (capture_recording.h).
#include "capture_recording.h"

#include <algorithm>
#include <atomic>

#include "capture_reduce_jobs.h"

namespace asval {
namespace recording {

void KeepOpen(const CaptureContext& ctx, CaptureRun& run, std::size_t copies_before) {
  if (copies_before == 0 && !run.copies.empty()) run.aliases_epoch = ctx.aliases.Epoch();
  if (!run.Empty()) run.Open(ctx.state.command_buffers.open_capture_runs());
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
