#include "capture_tracker.h"

#include <algorithm>
#include <new>

#include "layer_fences.h"

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

VkFence CaptureTracker::TakeFence() { return TakeLayerFence(device_, next_, mutex_, free_fences_); }

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

namespace {

// The queues a pass over the pending submissions found blocked: one of their submissions is still pending, so the
// later ones wait (a queue completes in submission order). Fixed size: a pass that meets more queues stops early.
class BlockedQueues {
 public:
  bool Contains(VkQueue queue) const { return std::find(queues_, queues_ + count_, queue) != queues_ + count_; }
  bool Add(VkQueue queue) {
    if (count_ == kMax) return false;
    queues_[count_++] = queue;
    return true;
  }

 private:
  static constexpr std::size_t kMax = 32;
  VkQueue queues_[kMax] = {};
  std::size_t count_ = 0;
};

// A submission whose judgement needs what another still-pending submission fills: an update compared with a source
// built by an earlier submission on another queue, a deserialization of bytes serialized by one. Filled in this
// submission itself, they are read in order when it is processed.
bool NeedsPendingFill(const SubmissionCaptures& c) {
  for (const ActivityComparison& update : c.comparisons) {
    if (!update.before || update.before->status() != BuildActivity::Status::kPending) continue;
    if (std::find(c.fills.begin(), c.fills.end(), update.before) == c.fills.end()) return true;
  }
  for (const DeserializeCheck& d : c.deserializes) {
    if (!d.expected || d.expected->status != SerializedContent::Status::kPending) continue;
    bool own = false;
    for (const SerializeCapture& s : c.serializes) own |= s.content == d.expected;
    if (!own) return true;
  }
  return false;
}

}  // namespace

void CaptureTracker::Process(const Covered& covered, const OnComplete& on_complete) {
  if (t_processing) return;
  std::lock_guard<std::recursive_mutex> order(processing_);
  t_processing = true;
  // Which pending submissions the app's wait covers. On a queue, submissions up to the last one carrying a waited
  // app fence are covered: that fence signaled, so that submission completed, and the layer's fence of each earlier
  // one on that queue is at most a moment away. Other queues' submissions are not waited for (they may run long).
  {
    std::lock_guard<std::mutex> lock(mutex_);
    BlockedQueues fenced;  // queues with a waited app fence at or after the entry (walking backwards)
    for (std::size_t k = pending_.size(); k-- > 0;) {
      Pending& p = pending_[k];
      const bool waited = covered.fence_count != 0 && p.app_fence &&
                          std::find(covered.fences, covered.fences + covered.fence_count, p.app_fence) !=
                              covered.fences + covered.fence_count;
      if (waited && !fenced.Contains(p.queue)) fenced.Add(p.queue);  // full: fewer covered, polled instead
      p.covered = covered.all || (covered.queue && p.queue == covered.queue) || fenced.Contains(p.queue);
    }
  }
  // Completed submissions are processed in submission order per queue: a queue's pending submission holds back the
  // later ones on that queue only (and those that need what it fills), not other queues' completed work.
  BlockedQueues blocked;
  std::size_t k = 0;
  for (;;) {
    Pending current;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      bool found = false;
      for (; k < pending_.size(); ++k) {
        Pending& p = pending_[k];
        if (blocked.Contains(p.queue)) continue;
        bool done = false;
        if (covered.all || !NeedsPendingFill(p.captures)) {
          done = p.complete;
          if (!done && p.fence) {
            VkResult status = next_.GetFenceStatus(device_, p.fence);
            if (status == VK_NOT_READY && p.covered) {
              status = next_.WaitForFences(device_, 1, &p.fence, VK_TRUE, kCoveredWaitNs);
            }
            done = status == VK_SUCCESS;
          } else if (!done) {
            // The app's fence is alive while it names the submission (FenceRetired): polling it is safe.
            done = p.covered || (p.app_fence && next_.GetFenceStatus(device_, p.app_fence) == VK_SUCCESS);
          }
        }
        if (!done) {
          // Still pending (or the device was lost): later, in order. Too many queues to remember: stop here.
          if (!blocked.Add(p.queue)) k = pending_.size();
          continue;
        }
        current = std::move(p);
        pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(k));
        found = true;
        break;
      }
      if (!found) break;
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
