#include "capture_tracker.h"

#include <algorithm>
#include <new>

#include "failure_injection.h"

namespace asval {

namespace {

// Long enough for any work the app's own wait already saw complete; a hung device is not waited for forever.
constexpr uint64_t kCoveredWaitNs = 10ull * 1000 * 1000 * 1000;

thread_local bool t_processing = false;

}  // namespace

CaptureTracker::~CaptureTracker() {
  for (const Pending& p : pending_) {
    if (p.fence) next_.DestroyFence(device_, p.fence, nullptr);
  }
  for (VkFence f : free_fences_) next_.DestroyFence(device_, f, nullptr);
}

VkFence CaptureTracker::TakeFence() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!free_fences_.empty()) {
      VkFence f = free_fences_.back();
      free_fences_.pop_back();
      return f;
    }
  }
  VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  if (InjectedFailure(FailSite::kLayerFence)) return VK_NULL_HANDLE;  // the test hook: as if vkCreateFence failed
  if (!next_.CreateFence || next_.CreateFence(device_, &info, nullptr, &fence) != VK_SUCCESS) return VK_NULL_HANDLE;
  return fence;
}

void CaptureTracker::Reserve(const SubmissionCaptures& captures) {
  std::lock_guard<std::recursive_mutex> order(processing_);
  for (const std::shared_ptr<CaptureLog>& log : captures.logs) log->SubmissionStarted();
}

void CaptureTracker::Unreserve(const SubmissionCaptures& captures) {
  std::lock_guard<std::recursive_mutex> order(processing_);
  for (const std::shared_ptr<CaptureLog>& log : captures.logs) log->SubmissionEnded();
}

// With the processing lock held: a submission's captures that will never be read. Their activity and serialized
// content are unknown (later updates of those structures are skipped and counted), and the checks they carried
// for this submission are counted as not run.
void CaptureTracker::Unread(SubmissionCaptures& captures) {
  for (const std::shared_ptr<BuildActivity>& node : captures.fills) node->MarkUnknown();
  // Serialized content never filled: the deserializations that read it stay unknown.
  for (SerializeCapture& s : captures.serializes) s.content->status = SerializedContent::Status::kUnknown;
  if (FailureCounters* failures = captures.failures) {
    failures->submissions_captures_unread.fetch_add(1, std::memory_order_relaxed);
    failures->capture_checks_unread.fetch_add(
        captures.comparisons.size() + captures.instance_checks.size() + captures.indirect_checks.size(),
        std::memory_order_relaxed);
  }
}

void CaptureTracker::Track(VkQueue queue, VkFence app_fence, VkFence layer_fence, SubmissionCaptures&& captures) {
  if (!app_fence && !layer_fence) {
    // No fence to tell when the bytes are there (the submission had none, and the layer's own could not be made:
    // TakeFence): nothing is read (unknown).
    if (captures.failures) captures.failures->inserted_failures.fetch_add(1, std::memory_order_relaxed);
    {
      std::lock_guard<std::recursive_mutex> order(processing_);
      Unread(captures);
    }
    Unreserve(captures);
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  Pending p;
  p.queue = queue;
  p.app_fence = app_fence;
  p.fence = layer_fence;
  p.captures = std::move(captures);
  try {
    pending_.push_back(std::move(p));
  } catch (const std::bad_alloc&) {
    // Not tracked: never read. (The layer's fence, if any, went down with the submission and is left to the
    // driver: it cannot be destroyed while that submission may be pending.)
    if (p.captures.failures) p.captures.failures->allocation_failures.fetch_add(1, std::memory_order_relaxed);
    std::lock_guard<std::recursive_mutex> order(processing_);
    Unread(p.captures);
    for (const std::shared_ptr<CaptureLog>& log : p.captures.logs) log->SubmissionEnded();
    return;
  }
  pending_count_.fetch_add(1, std::memory_order_release);
  peak_pending_ = std::max(peak_pending_, pending_.size());
}

void CaptureTracker::AddFootprint(CaptureFootprint* out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  out->pending_submissions += pending_.size();
  out->peak_pending_submissions += peak_pending_;
  out->spare_fences += free_fences_.size();
}

void CaptureTracker::ReturnFence(VkFence fence) {
  // After a failed submission its state is not known for sure: not reused.
  if (fence) next_.DestroyFence(device_, fence, nullptr);
}

void CaptureTracker::FenceRetired(VkFence app_fence) {
  if (!app_fence || idle()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (Pending& p : pending_) {
    if (p.app_fence != app_fence) continue;
    p.complete = true;
    p.app_fence = VK_NULL_HANDLE;
  }
}

// With the processing lock held.
void CaptureTracker::Retire(Pending& p) {
  for (const std::shared_ptr<CaptureLog>& log : p.captures.logs) log->SubmissionEnded();
  if (!p.fence) return;
  try {
    free_fences_.push_back(p.fence);
    next_.ResetFences(device_, 1, &p.fence);
  } catch (const std::bad_alloc&) {
    next_.DestroyFence(device_, p.fence, nullptr);  // not kept for reuse: its submission completed
    if (p.captures.failures) p.captures.failures->allocation_failures.fetch_add(1, std::memory_order_relaxed);
  }
  p.fence = VK_NULL_HANDLE;
}

void CaptureTracker::Process(const Covered& covered, const OnComplete& on_complete) {
  if (t_processing) return;
  std::lock_guard<std::recursive_mutex> order(processing_);
  t_processing = true;
  // On a queue, submissions up to the last one carrying a waited app fence are covered: that fence signaled, so
  // that submission completed, and the layer's fence of each earlier one on that queue is at most a moment away.
  // Other queues' submissions are not waited for (they may run long); processing stops at the first of them
  // still pending, and goes on at the next wait or submission.
  std::vector<std::pair<VkQueue, std::size_t>> covered_until;  // per queue: entries [0, index) of it are covered
  try {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t k = 0; k < pending_.size() && covered.fence_count != 0; ++k) {
      const Pending& p = pending_[k];
      if (!p.app_fence || std::find(covered.fences, covered.fences + covered.fence_count, p.app_fence) ==
                              covered.fences + covered.fence_count) {
        continue;
      }
      bool known = false;
      for (auto& [queue, until] : covered_until) {
        if (queue == p.queue) until = k + 1, known = true;
      }
      if (!known) covered_until.emplace_back(p.queue, k + 1);
    }
  } catch (const std::bad_alloc&) {
    // The app's fences then cover nothing here: what completed is still processed (its own or the layer's fence
    // polled), the rest at the next wait, submission or vkDestroyDevice.
    covered_until.clear();
  }
  const auto fence_covers = [&](const Pending& p, std::size_t k) {
    for (const auto& [queue, until] : covered_until) {
      if (queue == p.queue && k < until) return true;
    }
    return false;
  };
  for (std::size_t k = 0;; ++k) {
    Pending current;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pending_.empty()) break;
      Pending& p = pending_.front();
      // The app's wait covers it: its queue or device went idle, or a fence signaled whose first scope holds it
      // (a fence signal covers every earlier submission to its queue).
      const bool covered_here = covered.all || (covered.queue && p.queue == covered.queue) || fence_covers(p, k);
      bool done = p.complete;
      if (!done && p.fence) {
        VkResult status = next_.GetFenceStatus(device_, p.fence);
        if (status == VK_NOT_READY && covered_here) {
          status = next_.WaitForFences(device_, 1, &p.fence, VK_TRUE, kCoveredWaitNs);
        }
        done = status == VK_SUCCESS;
      } else if (!done) {
        // The app's fence is alive while it names the submission (FenceRetired): polling it is safe.
        done = covered_here || (p.app_fence && next_.GetFenceStatus(device_, p.app_fence) == VK_SUCCESS);
      }
      if (!done) break;  // still pending (or the device was lost): later, in order
      current = std::move(p);
      pending_.pop_front();
    }
    try {
      on_complete(current.captures);
    } catch (const std::bad_alloc&) {
      // The layer's allocation failed while this submission's captures were read (the builder's records, a
      // finding): what was not read is unknown, counted; the app's wait returns as it would have.
      if (current.captures.failures) {
        current.captures.failures->allocation_failures.fetch_add(1, std::memory_order_relaxed);
      }
      Unread(current.captures);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    Retire(current);
    // Pending until its findings are out: a wait hook that finds the tracker idle returns at once, and must not
    // return before another thread's processing of the submission it waited for has reported.
    pending_count_.fetch_sub(1, std::memory_order_release);
  }
  t_processing = false;
}


}  // namespace asval
