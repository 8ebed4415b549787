#include "history_host.h"

#include <fmt/format.h>

#include <array>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include "activity_rules.h"
#include "capture_skip.h"
#include "history_apply.h"
#include "history_findings.h"
#include "history_recorder.h"
#include "update_rules.h"

namespace asval {

namespace {

// A host update whose inputs were captured when it was called, paired with its source's activity as the history
// holds it now (the host build runs now): compared outside the store's lock, since it reports.
void CollectActivityComparison(const HistoryStore& store, const AsOp& op, std::vector<ActivityComparison>& out) {
  if (!op.is_update() || !op.capture_log) return;
  out.push_back(ComparisonWithSource(
      store, op,
      std::make_shared<BuildActivity>(op.capture_log->shared_from_this(), op.capture_info, op.origin, op.dst)));
}

}  // namespace

// A host command's history checks not run: its operations could not be recorded (a lost batch), or the layer's
// allocation failed while checking them. Counted as skipped for unknown history, once per command.
void HostChecksSkipped(const CheckContext& ctx) {
  ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
  ctx.state.history.store.rules_skipped_unknown_history.fetch_add(1, std::memory_order_relaxed);
}

bool ValidateHostOps(const CheckContext& ctx, const OpBatch& batch, const char* function) {
  if (!ctx.state.history_tracked || (batch.empty() && !batch.lost())) return false;
  if (batch.lost()) {
    ctx.state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
    HostChecksSkipped(ctx);
    return false;
  }
  HistoryFindings findings;
  std::vector<ActivityComparison> activity;
  try {
    std::unique_lock<std::mutex> lock = ctx.state.history.store.Lock();
    const HistoryCheckSite site{Location(function), VK_NULL_HANDLE, false};
    for (const AsOp& op : batch.ops()) {
      CheckOpHistory(ctx.state, ctx.state.history.store, ctx.enabled_checks, batch, op, site, findings);
      if (ctx.Enabled(kCheckHistory)) CollectActivityComparison(ctx.state.history.store, op, activity);
    }
  } catch (const std::bad_alloc&) {
    // Half checked: nothing is reported (a finding list cut short says less than it seems), counted.
    ctx.state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
    HostChecksSkipped(ctx);
    return false;
  }
  bool skip = findings.ReportAll(ctx.reporter);  // no lock held: the app's callback may call Vulkan
  for (ActivityComparison& update : activity) {
    try {
      update.after->Fill();  // this call's own record, not shared yet
    } catch (const std::bad_alloc&) {
      update.after->MarkUnknown();  // judged as bytes not captured: skipped and counted
      ctx.state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
    }
    skip |= CheckUpdateActivity(ctx, update);
  }
  return skip;
}

bool ValidateBuildHistory(const CheckContext& ctx, const BuildCommand& cmd) {
  if (!cmd.is_host() || !cmd.infos) return false;  // device builds: checked at submission
  return ValidateHostOps(
      ctx,
      HostBuildOps(cmd.info_count, cmd.infos, cmd.ranges, cmd.host_capture, cmd.host_captured,
                   ctx.state.properties.acceleration_structure.maxGeometryCount),
      cmd.function);
}

namespace {

// The layer's own failures (failure_counters.h): what each made unknown, and that its checks were skipped and
// counted. Said only when something failed.
void ReportFailureSummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  const FailureCounters& f = state.failures();
  const uint64_t reports_lost = reporter.ReportsLost();
  if (!f.any() && reports_lost == 0) return;
  const auto n = [](const std::atomic<uint64_t>& counter) { return counter.load(std::memory_order_relaxed); };
  reporter.Report(
      Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"), {Obj(VK_OBJECT_TYPE_DEVICE, device)},
      fmt::format("The layer's own failures: it could not allocate {} times ({} objects left untracked, {} "
                  "command-buffer recordings lost, {} host commands' operations lost, {} submissions whose history "
                  "could not be applied with {} operations left unchecked, {} structures' histories made unknown, "
                  "{} commands' captures dropped); capture memory could not be had {} times (those infos were "
                  "not captured); its own Vulkan objects (fence, reducing pipeline) could not be made {} times ({} "
                  "submissions' captures never read, {} capture checks not run{}); {} messages could not be built. "
                  "What these left unknown was skipped and counted, never guessed; the app's calls went through with "
                  "their own results.",
                  n(f.allocation_failures), n(f.objects_untracked), n(f.recordings_lost), n(f.host_commands_lost),
                  n(f.submissions_unknown), n(f.operations_unchecked), n(f.structures_made_unknown),
                  n(f.capture_commands_dropped), n(f.capture_memory_failures), n(f.inserted_failures),
                  n(f.submissions_captures_unread), n(f.capture_checks_unread),
                  f.reduce_pipeline_failed.load(std::memory_order_relaxed)
                      ? "; the reducing pipeline failed, so the captures were copied instead"
                      : "",
                  reports_lost));
}

// Execution order across queues (submission_order.h): said only when a batch had to wait or could not be ordered.
void ReportOrderSummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  const OrderCounters& c = state.history.order.counters;
  const auto n = [](const std::atomic<uint64_t>& counter) { return counter.load(std::memory_order_relaxed); };
  if (n(c.batches_deferred) == 0 && n(c.batches_unordered) == 0 && n(c.batches_never_resolved) == 0) return;
  reporter.Report(
      Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"), {Obj(VK_OBJECT_TYPE_DEVICE, device)},
      fmt::format("Execution order across queues: {} submitted batches waited for a timeline semaphore value not yet "
                  "signaled (or came after one on their queue) and were applied and checked when it was signaled "
                  "(their captures were not read); {} batches waited on a semaphore shared outside the layer's view "
                  "for a value it had not seen signaled, or could not be kept: their {} operations were not checked "
                  "and every structure's history was made unknown; {} batches were still waiting at vkDestroyDevice "
                  "and were never applied. Skipped and counted, never guessed.",
                  n(c.batches_deferred), n(c.batches_unordered), n(c.operations_unordered),
                  n(c.batches_never_resolved)));
}

}  // namespace

void ReportHistorySummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  ReportFailureSummary(state, reporter, device);
  const HistoryStore& store = state.history.store;
  const uint64_t skipped = store.rules_skipped_unknown_history.load(std::memory_order_relaxed);
  const CaptureCounters& capture = state.capture_counters;
  const uint64_t not_captured = capture.InfosNotCaptured();
  if (not_captured != 0 || capture.infos_captured.load(std::memory_order_relaxed) != 0) {
    // Each reason by its name (capture_skip.h): in the text those not zero, in the JSON line's "capture_skipped"
    // every one, zeros included, so that a tool finds each name in every such line.
    std::array<NamedCount, kCaptureSkipCount> reasons;
    std::string named;
    for (std::size_t r = 0; r < kCaptureSkipCount; ++r) {
      const CaptureSkip why = static_cast<CaptureSkip>(r);
      reasons[r] = NamedCount{NameOf(why), capture.NotCapturedFor(why)};
      if (reasons[r].count != 0) named += fmt::format(" {}={}", reasons[r].name, reasons[r].count);
    }
    const std::string text =
        fmt::format("Execution-time capture: {} build infos captured ({} bytes), {} updates judged on their captured "
                    "activity; {} infos that a rule needed could not be captured{}{} (their rules were skipped and "
                    "counted; docs/capture.md says what each reason means). The captures were recorded at {} capture "
                    "points (one per run of build commands and one per serialized blob).",
                    capture.infos_captured.load(std::memory_order_relaxed),
                    capture.bytes_captured.load(std::memory_order_relaxed),
                    capture.updates_compared.load(std::memory_order_relaxed), not_captured,
                    not_captured != 0 ? ":" : "", named,
                    capture.capture_points.load(std::memory_order_relaxed));
    const NamedCounts counts{kCaptureSkippedField, reasons.data(), reasons.size()};
    const Location where("vkDestroyDevice");
    // What went unchecked reaches the report file (the gate) even when report_flags leaves info out.
    if (not_captured != 0) {
      reporter.ReportUnchecked(kHistorySummaryId, where, {Obj(VK_OBJECT_TYPE_DEVICE, device)}, text, counts);
    } else {
      reporter.Report(Severity::kInfo, kHistorySummaryId, where, {Obj(VK_OBJECT_TYPE_DEVICE, device)}, text, counts);
    }
  }
  const uint64_t blobs = capture.blobs_captured.load(std::memory_order_relaxed);
  const uint64_t blobs_missed = capture.blobs_not_captured.load(std::memory_order_relaxed);
  if (blobs != 0 || blobs_missed != 0) {
    reporter.Report(Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"),
                    {Obj(VK_OBJECT_TYPE_DEVICE, device)},
                    fmt::format("Execution-time capture of device serialization: serialized bytes captured {} times "
                                "(serializations and deserializations), not captured {} times (memory the layer "
                                "could not read, or over capture_budget_mb); {} "
                                "deserializations of device bytes restored their history (the bytes read matched "
                                "what was serialized there), {} left it unknown.",
                                blobs, blobs_missed,
                                capture.deserializations_restored.load(std::memory_order_relaxed),
                                capture.deserializations_unverified.load(std::memory_order_relaxed)));
  }
  if (const uint64_t unknown = state.checks_skipped_unknown_state.load(std::memory_order_relaxed)) {
    reporter.Report(Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"),
                    {Obj(VK_OBJECT_TYPE_DEVICE, device)},
                    fmt::format("{} checks were skipped because the state they need was unknown (a limit the driver "
                                "did not report, an object or command buffer the layer did not see, sizes the layer "
                                "could not ask for, such as those of a geometry type newer than its headers, or bytes "
                                "it could not capture): skipped, never guessed.",
                                unknown));
  }
  ReportOrderSummary(state, reporter, device);
  if (skipped == 0) return;
  reporter.Report(Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"),
                  {Obj(VK_OBJECT_TYPE_DEVICE, device)},
                  fmt::format("{} history checks were skipped because the history they need was unknown "
                              "({} structures got an unknown history: deserialized from bytes the layer could not "
                              "verify, copied from such a structure, written by a command buffer the layer did not "
                              "see recorded, or operations the layer could not record or apply). "
                              "{} operations were applied in execution order.",
                              skipped, store.structures_made_unknown.load(std::memory_order_relaxed),
                              store.ops_applied.load(std::memory_order_relaxed)));
}

}  // namespace asval
