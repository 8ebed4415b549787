#include "submission.h"

namespace asval {

bool RecordedOf(const DeviceState& state, VkCommandBuffer cb, std::shared_ptr<const RecordedOps>* ops) {
  const std::shared_ptr<CommandBufferState> record = state.command_buffers.Find(cb);
  if (!record) return true;  // never seen allocated: unknown
  *ops = record->Executable();
  return *ops != nullptr;
}

HistorySubmission::~HistorySubmission() {
  if (!txn_) {
    if (store_lock_.owns_lock()) store_lock_.unlock();
    return;
  }
  // The undo log goes back to the store for the next submission, emptied first without the lock: the histories
  // it held may release the last references to captured bytes.
  if (store_lock_.owns_lock()) store_lock_.unlock();
  txn_->Clear();
  store_lock_ = state_.history.store.Lock();
  try {
    state_.history.store.ReturnTransaction(std::move(txn_));
  } catch (const std::bad_alloc&) {
    // Not kept as a spare (freed): nothing is lost but its capacity.
  }
  store_lock_.unlock();
}

void HistorySubmission::Begin() {
  if (!order_lock_.owns_lock()) order_lock_ = std::unique_lock<std::recursive_mutex>(state_.history.submission_order);
  if (!store_lock_.owns_lock()) store_lock_ = state_.history.store.Lock();
  if (!txn_) txn_ = state_.history.store.TakeTransaction();
}

void HistorySubmission::ApplyFailed(std::size_t unchecked) {
  FailureCounters& failures = state_.failures();
  failures.allocation_failures.fetch_add(1, std::memory_order_relaxed);
  failures.submissions_unknown.fetch_add(1, std::memory_order_relaxed);
  failures.operations_unchecked.fetch_add(unchecked, std::memory_order_relaxed);
  // Begin may have failed after taking the locks (they allocate nothing) but before the undo log.
  if (!order_lock_.owns_lock()) order_lock_ = std::unique_lock<std::recursive_mutex>(state_.history.submission_order);
  if (!store_lock_.owns_lock()) store_lock_ = state_.history.store.Lock();
  MakeAllUnknownAfterFailure(state_, state_.history.store);
}

std::size_t HistorySubmission::ApplyUnordered(const std::shared_ptr<const RecordedOps>& ops) {
  if (!state_.history_tracked) return 0;
  const std::size_t unchecked = ops && !ops->lost ? ops->batch.ops().size() : 0;
  try {
    Begin();
    ApplyUnknownCommandBuffer(state_, state_.history.store, txn_.get());
  } catch (const std::bad_alloc&) {
    ApplyFailed(0);
  }
  return unchecked;
}

void HistorySubmission::Undo() {
  captures_ = SubmissionCaptures{};  // nothing executes: nothing to read
  captures_.failures = &state_.failures();
  if (!txn_ || txn_->empty()) return;
  if (!store_lock_.owns_lock()) store_lock_ = state_.history.store.Lock();
  try {
    state_.history.store.Undo(*txn_);
  } catch (const std::bad_alloc&) {
    // Half undone: the histories may hold changes of a submission that did not happen. Unknown instead.
    FailureCounters& failures = state_.failures();
    failures.allocation_failures.fetch_add(1, std::memory_order_relaxed);
    failures.submissions_unknown.fetch_add(1, std::memory_order_relaxed);
    MakeAllUnknownAfterFailure(state_, state_.history.store);
  }
  store_lock_.unlock();
}

}  // namespace asval
