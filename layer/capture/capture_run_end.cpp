#include "capture_run_end.h"

#include <algorithm>

namespace asval {

namespace {

// Whether the buffer copy `c` reads is still alive: the layer's alias of its memory (not destroyed with the
// memory), or the app's dedicated buffer.
bool SourceAlive(const CaptureContext& ctx, const CaptureCopy& c) {
  if (c.memory != VK_NULL_HANDLE) {
    const std::shared_ptr<const MemoryAlias> alias = ctx.aliases.Find(c.memory);
    return alias && alias->buffer == c.src;
  }
  const std::optional<std::shared_ptr<const BufferState>> b = ctx.state.buffers.find(c.src);
  return b && *b;
}

// The slow path, taken only when some buffer was destroyed or some memory freed since the run's first copy was
// planned: the copies whose source is gone are left out, their infos no longer complete.
void LeaveOutStaleCopies(const CaptureContext& ctx, CaptureRun& run, CaptureLog* log) {
  std::size_t kept = 0;
  for (const CaptureCopy& c : run.copies) {
    if (SourceAlive(ctx, c)) {
      run.copies[kept++] = c;
      continue;
    }
    if (!log || c.info >= log->infos.size() || !log->infos[c.info].complete) continue;
    log->infos[c.info].complete = false;
    ctx.counters.infos_captured.fetch_sub(1, std::memory_order_relaxed);
    ctx.counters.NotCaptured(CaptureSkip::kUnknownAddress);
  }
  run.copies.resize(kept);
}

}  // namespace

void RecordCaptures(const CaptureContext& ctx, VkCommandBuffer cb, const std::vector<CaptureCopy>& copies,
                    const std::vector<CaptureDispatch>& dispatches, VkPipeline app_pipeline, VkEvent start_event) {
  const bool reduces = !dispatches.empty();
  VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  before.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  before.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | (reduces ? VK_ACCESS_SHADER_READ_BIT : 0);
  const VkPipelineStageFlags capture_stages =
      VK_PIPELINE_STAGE_TRANSFER_BIT | (reduces ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : 0);
  if (start_event != VK_NULL_HANDLE) {
    ctx.next.CmdWaitEvents(cb, 1, &start_event, kRunStartStages, capture_stages, 1, &before, 0, nullptr, 0, nullptr);
  } else {
    ctx.next.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, capture_stages, 0, 1, &before, 0, nullptr, 0,
                                nullptr);
  }
  for (const CaptureCopy& c : copies) ctx.next.CmdCopyBuffer(cb, c.src, c.dst, 1, &c.region);
  if (reduces) {
    VkPipeline bound = VK_NULL_HANDLE;
    for (const CaptureDispatch& d : dispatches) {
      if (d.pipeline != bound) ctx.next.CmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, bound = d.pipeline);
      // One Y row per job (capture_reducer.h): its parameters are found from the dispatch's base group.
      ctx.next.CmdDispatchBase(cb, 0, d.first_job % 32768, d.first_job / 32768, d.groups, d.jobs, 1);
    }
    if (app_pipeline != VK_NULL_HANDLE) ctx.next.CmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, app_pipeline);
  }
  // Later writes into the same capture bytes (a command buffer executed twice: a secondary's next execution after
  // the layer saved these bytes, capture_saves.h, or a primary listed twice, whose captures are then unknown) are
  // ordered after these writes too: without them here they would race (a write-after-write hazard that
  // synchronization validation reports).
  VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  after.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | (reduces ? VK_ACCESS_SHADER_WRITE_BIT : 0);
  after.dstAccessMask =
      VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | (reduces ? VK_ACCESS_SHADER_WRITE_BIT : 0);
  ctx.next.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | (reduces ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : 0),
                              VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &after, 0, nullptr,
                              0, nullptr);
  // After everything before it (the wait included: VUID-vkCmdResetEvent-event-03834), not before anything after.
  if (start_event != VK_NULL_HANDLE) ctx.next.CmdResetEvent(cb, start_event, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
}

void RecordCaptureRun(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording) {
  CaptureRun& run = recording.capture_run;
  if (!run.IsOpen()) return;
  if (!run.copies.empty() && ctx.aliases.Epoch() != run.aliases_epoch) {
    LeaveOutStaleCopies(ctx, run, recording.capture_log.get());
  }
  if (run.block.dispatch.jobs != 0) run.dispatches.push_back(run.block.dispatch);
  if (!run.copies.empty() || !run.dispatches.empty()) {
    RecordCaptures(ctx, cb, run.copies, run.dispatches, recording.compute_pipeline, run.start_event);
    ctx.counters.capture_points.fetch_add(1, std::memory_order_relaxed);
  } else if (run.start_event != VK_NULL_HANDLE) {
    // Nothing left to capture (every copy's source was destroyed): the event is still reset, as every execution
    // that sets it must.
    ctx.next.CmdResetEvent(cb, run.start_event, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
  }
  run.Close();
}

}  // namespace asval
