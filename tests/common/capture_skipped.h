#pragma once
// The "capture_skipped" field of the ASVAL-History-Summary lines of a JSON-lines report (issue 26: why a build info
// a rule needed was not captured): per reason name, its count summed over the lines (one per device). Tests compare
// it with counts written by hand.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace asval_test_common {

struct CaptureSkipped {
  std::map<std::string, uint64_t> counts;  // every name the field held, zeros included
  int lines = 0;                           // summary lines that held the field
  // The reasons counted at least once.
  std::map<std::string, uint64_t> NonZero() const {
    std::map<std::string, uint64_t> out;
    for (const auto& [name, n] : counts) {
      if (n != 0) out[name] = n;
    }
    return out;
  }
};

inline CaptureSkipped ReadCaptureSkipped(const std::vector<std::string>& report_lines) {
  CaptureSkipped out;
  for (const std::string& line : report_lines) {
    if (!nlohmann::json::accept(line)) continue;
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j.value("vuid", std::string()) != "ASVAL-History-Summary" || !j.contains("capture_skipped")) continue;
    ++out.lines;
    for (const auto& [name, n] : j["capture_skipped"].items()) out.counts[name] += n.get<uint64_t>();
  }
  return out;
}

}  // namespace asval_test_common
