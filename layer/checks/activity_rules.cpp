#include "activity_rules.h"

#include <fmt/format.h>

#include <array>
#include <string>

#include "build_report.h"

namespace asval {

namespace {

// Primitives named in a message; the rest are counted.
constexpr std::size_t kNamed = 8;

std::string Vuid(const ActivityComparison& c, const char* suffix) {
  return fmt::format("VUID-{}-{}", OpCommandName(c.update.command), suffix);
}

std::string Named(const std::array<builder::ActivityChange, kNamed>& changes, std::size_t reported, bool became_active,
                  uint64_t total) {
  std::string text;
  std::size_t named = 0;
  for (std::size_t k = 0; k < reported; ++k) {
    if (changes[k].becameActive != became_active) continue;
    text += named++ ? ", " : "";
    text += std::to_string(changes[k].primitive);
  }
  if (total > named) text += fmt::format(" (and {} more)", total - named);
  return text;
}

[[gnu::cold]] bool Report(const CheckContext& ctx, const ActivityComparison& c, uint32_t geometry, const char* suffix,
                          const std::string& what) {
  // The command, as the other findings at execution; the message names the info (DescribeOrigin) and geometry.
  const Location loc(OpCommandName(c.update.command));
  const std::string message = fmt::format(
      "{}: updates srcAccelerationStructure {} into {}; on execution, geometry {}: {}. The source's last executed "
      "build: {}.",
      DescribeOrigin(c.update), Hex(c.src), Hex(c.dst), geometry, what, DescribeOrigin(c.source_build));
  return ctx.reporter.Report(Severity::kError, Vuid(c, suffix), loc,
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.update.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.src),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst == c.src ? VK_NULL_HANDLE : c.dst)},
                      message);
}

}  // namespace

bool CheckUpdateActivity(const CheckContext& ctx, const ActivityComparison& c) {
  if (!c.before || !c.after || c.before->status() != BuildActivity::Status::kReady ||
      c.after->status() != BuildActivity::Status::kReady) {
    ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  bool skip = false;
  ctx.state.capture_counters.updates_compared.fetch_add(1, std::memory_order_relaxed);
  const auto& before = c.before->geometries();
  const auto& after = c.after->geometries();
  // A different geometry count is its own rule (pInfos-03758): the geometries both have are compared.
  const std::size_t count = before.size() < after.size() ? before.size() : after.size();
  for (std::size_t j = 0; j < count; ++j) {
    std::array<builder::ActivityChange, kNamed> changes{};
    const builder::ActivityDiff diff = builder::CompareActivity(before[j], after[j], changes.data(), changes.size());
    const uint32_t geometry = static_cast<uint32_t>(j);
    if (diff.becameActive != 0) {
      skip |= Report(ctx, c, geometry, "pInfos-03663",
             fmt::format("{} primitive(s) inactive in the source are active in the update: primitive {}",
                         diff.becameActive, Named(changes, diff.reported, true, diff.becameActive)));
    }
    if (diff.becameInactive != 0) {
      skip |= Report(ctx, c, geometry, "pInfos-03664",
             fmt::format("{} primitive(s) active in the source are inactive in the update (a NaN first vertex "
                         "component or AABB minX): primitive {}",
                         diff.becameInactive, Named(changes, diff.reported, false, diff.becameInactive)));
    }
    if (diff.indexHashDiffers) {
      skip |= Report(ctx, c, geometry, "pInfos-03768",
                     "the index values differ from those the source was last built with");
    }
  }
  return skip;
}

}  // namespace asval
