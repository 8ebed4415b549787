#pragma once
// The captures a recording has yet to record (issue 27): those of the run of build commands recorded since its
// last capture point. A build's captures are planned when the build is recorded (their bytes reserved in the
// recording's CaptureLog, the reduce jobs written), but the copies and the dispatch that fill them are recorded
// once for the whole run, at its end: the first command after it that can order a later write of the builds'
// inputs after their reads (a barrier, an event, a render pass, secondaries, the end of the command buffer),
// after a wait on the run's start event (set before its first build; a barrier where there is none) and before a
// barrier. So N build commands in a row cost the device one capture point instead of N
// (layer/capture/capture_run_end.h records it; docs/capture.md says why the bytes are the ones the builds read).
//
// Threads: written only by the thread recording the command buffer, like CommandBufferState::recording. Only
// `open_runs` (one per device) is read by other threads.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <vector>

namespace asval {

// A vkCmdCopyBuffer of the capture: from the layer's buffer over the app's memory (or a dedicated allocation's
// buffer) into the recording's slab. `memory`: the app's memory the source buffer is the layer's alias of (null:
// the source is the app's own dedicated buffer); `info`: the CaptureLog info it fills (index in infos), or
// UINT32_MAX for a serialized blob.
struct CaptureCopy {
  VkBuffer src = VK_NULL_HANDLE;
  VkBuffer dst = VK_NULL_HANDLE;
  VkBufferCopy region{};
  VkDeviceMemory memory = VK_NULL_HANDLE;
  uint32_t info = UINT32_MAX;
};

// One reducing dispatch (layer/capture/capture_reducer.h): its first job and how many follow it, and the X groups
// the largest needs.
struct CaptureDispatch {
  VkPipeline pipeline = VK_NULL_HANDLE;
  uint32_t first_job = 0;
  uint32_t jobs = 0;
  uint32_t groups = 0;
};

// Consecutive reduce jobs in the recording's log (a slab the reducer's table holds, within its first
// kReduceJobsPerSlab jobs): room for `capacity` of them, `dispatch.jobs` taken. Filled by layer/capture
// (capture_reduce_jobs.h: AcquireJobs, AddJob); kept open from one build command of a run to the next, so that
// the run's jobs go out in a few dispatches.
struct JobBlock {
  bool ok = false;
  uint8_t* slots = nullptr;
  CaptureDispatch dispatch;
  uint32_t capacity = 0;
  uint32_t Room() const { return ok ? capacity - dispatch.jobs : 0; }
};

class CaptureRun {
 public:
  std::vector<CaptureCopy> copies;
  std::vector<CaptureDispatch> dispatches;  // blocks closed during the run (the open one is `block`)
  JobBlock block;
  // MemoryAliases::Epoch() when the run's first copy was planned: a copy's source buffer may have been destroyed
  // since only if it changed (the app freed memory while recording).
  uint64_t aliases_epoch = 0;
  // The event set right before the run's first build (null: none, the capture point then waits with a barrier):
  // its capture point waits for what came before the run, not for the run's builds (docs/capture.md).
  VkEvent start_event = VK_NULL_HANDLE;

  bool Empty() const { return copies.empty() && dispatches.empty() && block.dispatch.jobs == 0; }
  bool IsOpen() const { return counted_ != nullptr; }
  // The run holds captures to record: counted in `open_runs` (the device's) until Close.
  void Open(std::atomic<uint32_t>& open_runs) {
    if (counted_) return;
    counted_ = &open_runs;
    open_runs.fetch_add(1, std::memory_order_acq_rel);
  }
  // Recorded, or dropped with its recording (vkBeginCommandBuffer, vkResetCommandBuffer, a pool reset, a free):
  // empty again, its storage kept for the next run.
  void Close() {
    copies.clear();
    dispatches.clear();
    block = JobBlock{};
    start_event = VK_NULL_HANDLE;  // the recording's log keeps it
    if (counted_) counted_->fetch_sub(1, std::memory_order_acq_rel);
    counted_ = nullptr;
  }
  CaptureRun() = default;
  CaptureRun(const CaptureRun&) = delete;
  CaptureRun& operator=(const CaptureRun&) = delete;
  // Not counted down here: the device's counter may be gone when the last holder of a command buffer's state lets
  // it go. CommandBufferMap closes the run of every command buffer it forgets.
  ~CaptureRun() = default;

 private:
  std::atomic<uint32_t>* counted_ = nullptr;
};

}  // namespace asval
