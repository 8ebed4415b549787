#pragma once
// The history rules at vkQueueSubmit (layer/checks: const, they only report). HistorySubmission
// (layer/state/submission.h) applies each submitted operation to the histories and calls the check returned
// by For() just before, so each operation is judged against what the operations before it left. Findings are
// collected while the history lock is held and reported after it is released.
#include <vulkan/vulkan.h>

#include "check_context.h"
#include "history_findings.h"
#include "update_rules.h"

namespace asval {

class SubmitChecks {
 public:
  // submission: the HistorySubmission's id (SubmissionCaptures::id), which the operations are judged within.
  // submitted_at: the id when the app submitted them (0: `submission`; a deferred batch's is older).
  SubmitChecks(const CheckContext& ctx, uint64_t submission = 0, uint64_t submitted_at = 0)
      : ctx_(ctx), submission_(submission), submitted_at_(submitted_at ? submitted_at : submission) {}

  // The check for the operations of one submitted command buffer; loc names it in the call's parameters.
  auto For(VkCommandBuffer cb, const Location& loc) {
    return [this, site = HistoryCheckSite{loc, cb, true, submission_, submitted_at_}](
               const HistoryStore& store, const OpBatch& batch, const AsOp& op) {
      CheckOpHistory(ctx_.state, store, ctx_.enabled_checks, batch, op, site, findings_);
    };
  }
  // Reports every finding (call with no lock held). True when a callback asked to skip the submission.
  bool ReportAll() const { return !findings_.empty() && findings_.ReportAll(ctx_.reporter); }

 private:
  const CheckContext& ctx_;
  uint64_t submission_ = 0;
  uint64_t submitted_at_ = 0;
  HistoryFindings findings_;
};

}  // namespace asval
