#pragma once
// One queue submission's effect on the build history, applied speculatively and committed or rolled back:
//
//   HistorySubmission submission(state);
//   for each submitted command buffer: submission.Apply(cb, check);  // check(store, batch, op) runs before
//                                                                    // each op is applied (const: layer/checks)
//   submission.EndApply();                 // the store's lock is released: findings may now be reported
//   if (skip) { submission.Undo(); ... }   // a callback asked to skip the call
//   result = downcall; if (result != VK_SUCCESS) submission.Undo();
//
// From the first command buffer with operations until the object is destroyed (after the downcall), the
// device's submission_order lock is held: a submission on another queue waits, so it is never checked against
// changes that are then undone. Submissions are rare next to recorded commands, and one order gives every
// submission a single total order, which is the order the layer assumes the device executes them in (host
// submission order; see docs/history.md).
//
// The order lock is recursive, so an app callback that reports a finding of this submission may itself submit on
// this thread. A callback that instead waits for another thread which submits on this device would wait forever
// (that thread waits for the order lock): an unusual callback, and the price of never checking one submission
// against another's changes that are then undone.
#include <vulkan/vulkan.h>

#include <mutex>
#include <new>

#include "device_state.h"
#include "history_apply.h"

namespace asval {

// False when the command buffer does nothing to structures; *ops null when what it does is unknown (a command
// buffer the layer never saw allocated).
bool RecordedOf(const DeviceState& state, VkCommandBuffer cb, std::shared_ptr<const RecordedOps>* ops);

class HistorySubmission {
 public:
  explicit HistorySubmission(DeviceState& state) : state_(state) {
    captures_.failures = &state.failures();
    captures_.id = state.NextObjectId();
  }
  HistorySubmission(const HistorySubmission&) = delete;
  HistorySubmission& operator=(const HistorySubmission&) = delete;
  ~HistorySubmission();

  // Applies the operations of one submitted command buffer, in recording order, calling
  // check(const HistoryStore&, const OpBatch&, const AsOp&) before each. An allocation failure (the layer's, in
  // the apply or in a check) stops this command buffer there: every structure's history is made unknown from that
  // point on (not undone with the submission: unknown is never wrong), and the operations whose checks did not run
  // are counted (ApplyFailed). Nothing is thrown to the hook.
  template <typename Check>
  void Apply(VkCommandBuffer cb, Check&& check) {
    if (!state_.history_tracked) return;
    std::shared_ptr<const RecordedOps> ops;
    if (!RecordedOf(state_, cb, &ops)) return;  // most submitted command buffers build nothing: no lock
    ApplyRecorded(ops, check);
  }
  // The same for operations read earlier (RecordedOf; null: unknown), e.g. a batch deferred until the semaphore
  // it waits for is signaled (submission_order.h).
  template <typename Check>
  void ApplyRecorded(const std::shared_ptr<const RecordedOps>& ops, Check&& check) {
    if (!state_.history_tracked) return;
    std::size_t total = 0, checked = 0, applied = 0;
    try {
      Begin();
      HistoryStore& store = state_.history.store;
      if (!ops || ops->lost) {
        // A command buffer the layer never saw allocated, or whose operations it could not record.
        ApplyUnknownCommandBuffer(state_, store, txn_.get());
        return;
      }
      const OpBatch& batch = ops->batch;
      total = batch.ops().size();
      txn_->ReserveMore(total);  // one entry per written structure (clobbers are rare)
      SubmissionCaptures* captures = read_captures_ ? &captures_ : nullptr;
      for (const AsOp& op : batch.ops()) {
        check(static_cast<const HistoryStore&>(store), batch, op);
        ++checked;
        ApplyOp(state_, store, batch, op, txn_.get(), captures);
        ++applied;
      }
    } catch (const std::bad_alloc&) {
      ApplyFailed(total - checked);
    }
    ops_applied_ += applied;
    state_.history.store.ops_applied.fetch_add(applied, std::memory_order_relaxed);
  }
  // A batch whose place in execution order the layer cannot know (submission_order.h, kUnordered): every
  // structure's history becomes unknown, and its operations are not checked (returned: their count).
  std::size_t ApplyUnordered(const std::shared_ptr<const RecordedOps>& ops);
  // Applies without reading captures: the builds' activity stays unknown (a deferred batch went down before the
  // layer knew what it would capture, so its captures were not reserved: capture_tracker.h).
  void WithoutCaptures() { read_captures_ = false; }
  // Releases the store's lock (the order lock stays held until destruction).
  void EndApply() {
    if (store_lock_.owns_lock()) store_lock_.unlock();
  }
  // The submission did not happen (skipped, or rejected by the driver): its changes are undone.
  void Undo();

  uint64_t ops_applied() const { return ops_applied_; }
  // What the submission's captured builds ask for once it completes (empty after Undo).
  SubmissionCaptures& captures() { return captures_; }

 private:
  void Begin();
  // An allocation failed while applying: every structure unknown from here on, counted.
  void ApplyFailed(std::size_t unchecked);

  DeviceState& state_;
  // Declared before store_lock_: released after it.
  std::unique_lock<std::recursive_mutex> order_lock_;
  std::unique_lock<std::mutex> store_lock_;
  // From the store's spares when the first command buffer with operations is applied (null before).
  std::unique_ptr<Transaction> txn_;
  SubmissionCaptures captures_;
  uint64_t ops_applied_ = 0;
  bool read_captures_ = true;
};

}  // namespace asval
