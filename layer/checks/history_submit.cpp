#include "history_submit.h"

#include "history_apply.h"
#include "layer_settings.h"
#include "update_rules.h"

namespace asval {

bool HistoryTracked(uint32_t enabled_checks) { return (enabled_checks & (kCheckHistory | kCheckCopies)) != 0; }

SubmitHistory::SubmitHistory(DeviceState& state, Reporter& reporter, uint32_t enabled_checks)
    : state_(state), reporter_(reporter), enabled_(enabled_checks) {}

void SubmitHistory::Apply(VkCommandBuffer cb, const Location& loc) {
  if (!HistoryTracked(enabled_)) return;
  std::shared_ptr<CommandBufferLog> log = state_.history.command_buffers.Find(cb);
  // Most submitted command buffers build nothing: one map lookup and no lock.
  if (log && log->batch.empty() && !log->lost) return;
  HistoryStore& store = state_.history.store;
  if (!lock_.owns_lock()) lock_ = store.Lock();
  if (!log || log->lost) {
    // A command buffer the layer never saw allocated, or whose operations it could not record: what it does
    // to any structure is unknown from here on.
    store.MarkEverythingUnknown();
    return;
  }
  const HistoryCheckSite site{loc, cb, true};
  const OpBatch& batch = log->batch;
  txn_.ReserveMore(batch.ops().size() * 2);  // one entry per written structure, and some clobbers
  for (const AsOp& op : batch.ops()) {
    CheckOpHistory(state_, store, enabled_, batch, op, site, findings_);
    ApplyOp(state_, store, batch, op, &txn_);
    ++ops_applied_;
  }
}

bool SubmitHistory::Finish() {
  if (lock_.owns_lock()) lock_.unlock();
  if (findings_.empty()) return false;
  const bool skip = findings_.ReportAll(reporter_);
  if (skip) Undo();
  return skip;
}

void SubmitHistory::Undo() {
  if (lock_.owns_lock()) lock_.unlock();
  if (txn_.empty()) return;
  std::unique_lock<std::mutex> lock = state_.history.store.Lock();
  state_.history.store.Undo(txn_);
}

}  // namespace asval
