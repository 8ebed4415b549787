#pragma once
// Batches deferred until the semaphore values they wait for are signaled (layer/state/submission_order.h): applied,
// checked and reported, in an order the device can execute them in, by the call that signals those values (a
// submission on another queue, after its downcall; vkSignalSemaphore). With the device's submission_order lock held.
//
// Such a batch went down when it was submitted: a finding is reported now, and a callback's VK_TRUE cannot keep it
// from the driver. In protect mode an error found now is treated like an error judged at completion
// (docs/protect.md): every later submission on the device is withheld. Its captures were not reserved when it went
// down, so they are not read (its builds' activity stays unknown, counted in ASVAL-History-Summary).
#include <cstring>

#include "layer_data.h"
#include "submission.h"
#include "submit_checks.h"
#include "withhold.h"

namespace asval::hooks {

inline void ApplyDeferredBatch(DeviceData& data, const DeferredBatch& batch, bool unordered) {
  const CheckContext ctx = MakeCheckContext(data);
  HistorySubmission submission(data.state);
  submission.WithoutCaptures();
  SubmitChecks checks(ctx, submission.captures().id, batch.submitted_at);
  const bool submit2 = std::strcmp(batch.function, "vkQueueSubmit") != 0;
  const Location root(batch.function);
  std::size_t unchecked = 0;
  for (const DeferredCommandBuffer& cb : batch.command_buffers) {
    if (unordered) {
      unchecked += submission.ApplyUnordered(cb.ops);
      continue;
    }
    const Location submit = root.Field("pSubmits", cb.submit_index);
    const Location loc = submit2 ? submit.Field("pCommandBufferInfos", cb.cb_index).Field("commandBuffer")
                                 : submit.Field("pCommandBuffers", cb.cb_index);
    submission.ApplyRecorded(cb.ops, checks.For(cb.cb, loc));
  }
  submission.EndApply();
  OrderCounters& counters = data.state.history.order.counters;
  if (unordered) {
    counters.batches_unordered.fetch_add(1, std::memory_order_relaxed);
    counters.operations_unordered.fetch_add(unchecked, std::memory_order_relaxed);
  }
  const ProtectScope protect(data.reporter->protects());
  checks.ReportAll();  // the batch went down already: a VK_TRUE cannot keep it from the driver
  HaltSubmissionsAfter(data, protect, /*deferred=*/true);
}

// Every deferred batch whose waits are now met, in execution order.
inline void ApplyReadyBatches(DeviceData& data) {
  SubmissionOrder& order = data.state.history.order;
  if (order.backlog() == 0) return;
  DeferredBatch batch;
  bool unordered = false;
  while (order.TakeReady(&batch, &unordered)) {
    ApplyDeferredBatch(data, batch, unordered);
    order.Applied(batch);
  }
}

}  // namespace asval::hooks
