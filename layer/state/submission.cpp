#include "submission.h"

namespace asval {

bool HistorySubmission::Lookup(VkCommandBuffer cb, std::shared_ptr<const RecordedOps>* ops) const {
  const std::shared_ptr<CommandBufferState> record = state_.command_buffers.Find(cb);
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
  state_.history.store.ReturnTransaction(std::move(txn_));
  store_lock_.unlock();
}

void HistorySubmission::Begin() {
  if (!order_lock_.owns_lock()) order_lock_ = std::unique_lock<std::recursive_mutex>(state_.history.submission_order);
  if (!store_lock_.owns_lock()) store_lock_ = state_.history.store.Lock();
  if (!txn_) txn_ = state_.history.store.TakeTransaction();
}

void HistorySubmission::Undo() {
  captures_ = SubmissionCaptures{};  // nothing executes: nothing to read
  if (!txn_ || txn_->empty()) return;
  if (!store_lock_.owns_lock()) store_lock_ = state_.history.store.Lock();
  state_.history.store.Undo(*txn_);
  store_lock_.unlock();
}

}  // namespace asval
