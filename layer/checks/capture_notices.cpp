#include "capture_notices.h"

#include <fmt/format.h>

namespace asval {

void ReportUndefinedInput(const CheckContext& ctx, const BuildActivity& activity) {
  for (const BuildActivity::UndefinedInput& u : activity.undefined_input()) {
    const OpOrigin& origin = activity.origin();
    ctx.reporter.Report(
        Severity::kWarning, kUndefinedInputId, Location(OpCommandName(origin.command)),
        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, origin.command_buffer),
         Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, activity.dst())},
        fmt::format("{}: on execution, geometry {}: {} primitive(s) have a NaN component other than the first (X of a "
                    "vertex, minX of an AABB) while that one is not NaN, for which the specification leaves the "
                    "build's result undefined (first: primitive {}).",
                    DescribeOrigin(origin), u.geometry, u.primitives, u.first_primitive));
  }
}

void ReportCaptureBudget(const CheckContext& ctx, uint32_t budget_mb) {
  CaptureCounters& counters = ctx.state.capture_counters;
  if (counters.infos_over_budget.load(std::memory_order_relaxed) == 0 ||
      counters.budget_reported.exchange(true, std::memory_order_relaxed)) {
    return;
  }
  ctx.reporter.Report(Severity::kWarning, kCaptureBudgetId, Location("vkCmdBuildAccelerationStructuresKHR"), {},
                      fmt::format("A command buffer's captured build inputs would exceed capture_budget_mb ({} MB): the "
                                  "builds over it are not captured, and the rules that need their bytes are skipped "
                                  "and counted (ASVAL-History-Summary). Raise capture_budget_mb to check them. "
                                  "Reported once.",
                                  budget_mb));
}

}  // namespace asval
