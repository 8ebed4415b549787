#include "history_host.h"

#include <fmt/format.h>

#include <memory>
#include <mutex>
#include <vector>

#include "activity_rules.h"
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

bool ValidateHostOps(const CheckContext& ctx, const OpBatch& batch, const char* function) {
  if (!ctx.state.history_tracked || batch.empty()) return false;
  HistoryFindings findings;
  std::vector<ActivityComparison> activity;
  {
    std::unique_lock<std::mutex> lock = ctx.state.history.store.Lock();
    const HistoryCheckSite site{Location(function), VK_NULL_HANDLE, false};
    for (const AsOp& op : batch.ops()) {
      CheckOpHistory(ctx.state, ctx.state.history.store, ctx.enabled_checks, batch, op, site, findings);
      if (ctx.Enabled(kCheckHistory)) CollectActivityComparison(ctx.state.history.store, op, activity);
    }
  }
  bool skip = findings.ReportAll(ctx.reporter);  // no lock held: the app's callback may call Vulkan
  for (ActivityComparison& update : activity) {
    update.after->Fill();  // this call's own record, not shared yet
    skip |= CheckUpdateActivity(ctx, update);
  }
  return skip;
}

bool ValidateBuildHistory(const CheckContext& ctx, const BuildCommand& cmd) {
  if (!cmd.is_host() || !cmd.infos) return false;  // device builds: checked at submission
  return ValidateHostOps(
      ctx, HostBuildOps(cmd.info_count, cmd.infos, cmd.ranges, cmd.host_capture, cmd.host_captured), cmd.function);
}

void ReportHistorySummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  const HistoryStore& store = state.history.store;
  const uint64_t skipped = store.rules_skipped_unknown_history.load(std::memory_order_relaxed);
  const CaptureCounters& capture = state.capture_counters;
  const uint64_t not_captured = capture.infos_not_captured.load(std::memory_order_relaxed);
  if (not_captured != 0 || capture.infos_captured.load(std::memory_order_relaxed) != 0) {
    reporter.Report(Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"),
                    {Obj(VK_OBJECT_TYPE_DEVICE, device)},
                    fmt::format("Execution-time capture: {} build infos captured ({} bytes), {} updates judged on "
                                "their captured activity; {} infos that a rule needed could not be captured (their "
                                "rules were skipped and counted: a geometry kind or format not captured yet, a "
                                "buffer the layer could not copy, or over capture_budget_mb).",
                                capture.infos_captured.load(std::memory_order_relaxed),
                                capture.bytes_captured.load(std::memory_order_relaxed),
                                capture.updates_compared.load(std::memory_order_relaxed), not_captured));
  }
  const uint64_t blobs = capture.blobs_captured.load(std::memory_order_relaxed);
  const uint64_t blobs_missed = capture.blobs_not_captured.load(std::memory_order_relaxed);
  if (blobs != 0 || blobs_missed != 0) {
    reporter.Report(Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"),
                    {Obj(VK_OBJECT_TYPE_DEVICE, device)},
                    fmt::format("Execution-time capture of device serialization: serialized bytes captured {} times "
                                "(serializations and deserializations), not captured {} times (a buffer created "
                                "without TRANSFER_SRC, or over capture_budget_mb); {} "
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
  if (skipped == 0) return;
  reporter.Report(Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"),
                  {Obj(VK_OBJECT_TYPE_DEVICE, device)},
                  fmt::format("{} history checks were skipped because the history they need was unknown "
                              "({} structures got an unknown history: deserialized from bytes the layer could not "
                              "verify, copied from such a structure, written by a command buffer the layer did not "
                              "see recorded, or operations the layer could not record). "
                              "{} operations were applied in execution order.",
                              skipped, store.structures_made_unknown.load(std::memory_order_relaxed),
                              store.ops_applied.load(std::memory_order_relaxed)));
}

}  // namespace asval
