#pragma once
// Findings of the history rules, collected while the history lock is held and reported after it is released:
// the app's callback may call Vulkan (even a host build, which takes the same lock), so no lock of the layer's
// may be held while it runs. Formatting happens only when something is found.
#include <array>
#include <string>
#include <vector>

#include "location.h"
#include "reporter.h"
#include "severity.h"

namespace asval {

// The layer-specific id of a structure used after another operation wrote over its memory.
inline constexpr const char kClobberedId[] = "ASVAL-History-Clobbered";
// The layer-specific id of the summary of history checks skipped for unknown history (info, at vkDestroyDevice).
inline constexpr const char kHistorySummaryId[] = "ASVAL-History-Summary";
// The JSON key of the summary's counts of infos not captured, per reason (capture_skip.h; scripts/asval-run reads it).
inline constexpr const char kCaptureSkippedField[] = "capture_skipped";

struct HistoryFinding {
  Severity severity;
  std::string vuid;
  Location loc;
  std::array<ReportObject, 3> objects;
  std::string message;
};

class HistoryFindings {
 public:
  bool empty() const { return list_.empty(); }
  std::size_t size() const { return list_.size(); }
  const std::vector<HistoryFinding>& list() const { return list_; }

  void Add(Severity severity, std::string vuid, const Location& loc, std::array<ReportObject, 3> objects,
           std::string message) {
    list_.push_back(HistoryFinding{severity, std::move(vuid), loc, objects, std::move(message)});
  }

  // Reports every finding (no lock held). True when a callback asked to skip the call.
  bool ReportAll(Reporter& reporter) const {
    bool skip = false;
    for (const HistoryFinding& f : list_) {
      skip |= reporter.Report(f.severity, f.vuid, f.loc, {f.objects[0], f.objects[1], f.objects[2]}, f.message);
    }
    return skip;
  }

 private:
  std::vector<HistoryFinding> list_;
};

}  // namespace asval
