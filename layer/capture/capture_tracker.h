#pragma once
// Completion of submissions that carry captures (execution-time capture, issue 12). After such a submission
// succeeds, the layer submits an empty batch with a fence of its own to the same queue: it signals once all work
// submitted before it has completed. Completed submissions are processed in submission order (their captured
// builds' activity filled, then the update rules run on it) when the app learns of completion: in the wait
// hooks (after the app's wait returned, waiting for the layer's fence of each submission the app's wait covers:
// the work is done, so that fence signals at once), at the next submission when already complete, and at
// vkDestroyDevice. Findings are therefore reported before the app's wait returns.
//
// A fence on an empty submission rather than a timeline semaphore signal in the app's own submission: it needs
// no device feature the app may not have enabled and leaves the app's submission as it was.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <vector>

#include "build_activity.h"
#include "vk_dispatch_table.h"

namespace asval {

class CaptureTracker {
 public:
  // Which pending submissions the app's wait covers: their layer fence is waited for before processing.
  struct Covered {
    bool all = false;                   // vkDeviceWaitIdle, vkDestroyDevice
    VkQueue queue = VK_NULL_HANDLE;     // vkQueueWaitIdle
    const VkFence* fences = nullptr;    // vkWaitForFences / vkGetFenceStatus that returned VK_SUCCESS
    uint32_t fence_count = 0;
  };
  using OnComplete = std::function<void(SubmissionCaptures&)>;

  CaptureTracker(VkDevice device, const DeviceDispatchTable& next) : device_(device), next_(next) {}
  ~CaptureTracker();

  // Before the downcall of a submission that carries captures: its recordings count as pending from now on, so
  // that one already pending (a SIMULTANEOUS_USE command buffer, or one whose completion the layer has not seen
  // yet) is marked overlapped before the device can write its capture bytes again, and no reader is reading them
  // meanwhile (both under the processing lock).
  void Reserve(const SubmissionCaptures& captures);
  // The submission was not made (skipped, or rejected by the driver).
  void Unreserve(const SubmissionCaptures& captures);
  // It succeeded: the layer's fence follows it on `queue` (the app's fence, or null, names it for the waits).
  void Track(VkQueue queue, VkFence app_fence, SubmissionCaptures&& captures);
  // Processes, in submission order, every submission that completed, and those `covered` names (waiting for
  // their layer fence); stops at the first one still pending. A call made while this thread is processing (from
  // an app callback) does nothing.
  void Process(const Covered& covered, const OnComplete& on_complete);
  // No submission pending (one relaxed load: asked at every submission and wait).
  bool idle() const { return pending_count_.load(std::memory_order_acquire) == 0; }

 private:
  struct Pending {
    VkQueue queue;
    VkFence app_fence;
    VkFence fence;
    SubmissionCaptures captures;
  };
  VkFence TakeFence();
  void Retire(Pending& p);

  const VkDevice device_;
  const DeviceDispatchTable& next_;
  mutable std::mutex mutex_;          // pending_, free_fences_
  // One thread processes at a time, in order; also guards the logs' pending_submissions and overlapped.
  std::recursive_mutex processing_;
  std::deque<Pending> pending_;
  std::atomic<std::size_t> pending_count_{0};
  std::vector<VkFence> free_fences_;
};

}  // namespace asval
