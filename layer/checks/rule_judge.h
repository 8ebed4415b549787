#pragma once
// What a broken or unjudgeable per-geometry rule leads to. The per-geometry rules of the build families
// (structure, ranges, input alignment, input reads, instance counts) are each written once, as a template over
// the judge, and run two ways:
//   ScreeningJudge   the command's geometry pass (geometry_pass.h) runs every family's rules over each geometry
//                    once; a broken rule or one that cannot be judged only makes the rules return true (the
//                    info is flagged for that family): nothing is reported, nothing counted.
//   ReportingJudge   a family's own walk, over the infos flagged for it: reports (through the family's cold
//                    report function) and counts unknown state, exactly as a walk over every info would; the
//                    rules return the app callback's skip.
// A rule ORs what Broken and Unknown return into its result (a value in a register, not a judge in memory:
// the pass runs five families' rules per geometry).
// A family skips only infos for which its rules found nothing, so its findings, their order and the
// unknown-state counts are those of a walk over every info.
#include "build_report.h"
#include "check_context.h"

namespace asval {

struct ScreeningJudge {
  static constexpr bool kReports = false;
  template <typename Report>
  bool Broken(Report&&) const {
    return true;
  }
  bool Unknown() const { return true; }
};

struct ReportingJudge {
  static constexpr bool kReports = true;
  const CheckContext& ctx;
  // report() reports the finding and returns the callback's skip.
  template <typename Report>
  bool Broken(Report&& report) const {
    return report();
  }
  bool Unknown() const {
    CountUnknownState(ctx);
    return false;
  }
};

}  // namespace asval
