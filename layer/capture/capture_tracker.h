#pragma once
// Completion of submissions that carry captures (execution-time capture, issue 12). A submission with the app's
// own fence is complete once that fence is seen signaled (polled through the next element, or waited for by the
// app), or reset or destroyed by the app (both require the submission to have completed), or its queue or
// device waited idle. A submission without a fence gets one of the layer's, passed down in place of the app's
// VK_NULL_HANDLE (the app's submission is otherwise unchanged and cannot observe it). Completed submissions are
// processed in submission order per queue (their captured builds' activity filled, then the update rules run on
// it; one queue's pending submission does not hold back another queue's completed ones, except one that needs what
// the pending one fills) when the app learns of completion: in the wait
// hooks (after the app's wait returned, waiting for the layer's fence of each submission the app's wait covers:
// the work is done, so that fence signals at once), at the next submission when already complete, and at
// vkDestroyDevice. Findings are therefore reported before the app's wait returns.
//
// A fence rather than a timeline semaphore signal added to the app's submission: no device feature the app may
// not have enabled, no batch added, and no extra submission.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <vector>

#include "build_activity.h"
#include "footprint.h"
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
  // The fence to pass down with a submission that carries captures when the app gives none (null when none
  // could be made: its captures are then unknown).
  VkFence TakeFence();
  // The submission succeeded, with the app's fence or, when it gave none, layer_fence in its place. On failure
  // the layer's fence is given back with ReturnFence.
  void Track(VkQueue queue, VkFence app_fence, VkFence layer_fence, SubmissionCaptures&& captures);
  void ReturnFence(VkFence fence);
  // vkResetFences / vkDestroyFence of an app's fence: the submissions it was given to completed (the app may
  // reset or destroy a fence only then), and the handle no longer names them.
  void FenceRetired(VkFence app_fence);
  // Processes, in submission order per queue, every submission that completed, and those `covered` names (waiting
  // for their layer fence); on each queue, stops at the first one still pending. A call made while this thread is
  // processing (from an app callback) does nothing.
  void Process(const Covered& covered, const OnComplete& on_complete);
  // Adds its pending submissions and spare fences to the layer's footprint (footprint.h).
  void AddFootprint(CaptureFootprint* out) const;
  // No submission pending (one atomic load: asked at every submission and wait).
  bool idle() const { return pending_count_.load(std::memory_order_acquire) == 0; }

 private:
  struct Pending {
    VkQueue queue = VK_NULL_HANDLE;
    VkFence app_fence = VK_NULL_HANDLE;  // the app's fence, while it names this submission
    VkFence fence = VK_NULL_HANDLE;      // the layer's own, when the app gave none
    bool complete = false;               // known complete (its app fence was reset or destroyed)
    bool covered = false;                // the app's wait being processed covers it (Process)
    SubmissionCaptures captures;
  };
  void Retire(Pending& p);
  // A submission's captures that will never be read: unknown, counted (with the processing lock held).
  static void Unread(SubmissionCaptures& captures);

  const VkDevice device_;
  const DeviceDispatchTable& next_;
  mutable std::mutex mutex_;          // pending_, free_fences_
  // One thread processes at a time, in order; also guards the logs' pending submissions.
  std::recursive_mutex processing_;
  std::deque<Pending> pending_;
  std::atomic<std::size_t> pending_count_{0};
  std::vector<VkFence> free_fences_;
  std::size_t peak_pending_ = 0;  // the most submissions pending at once (footprint)
};

}  // namespace asval
