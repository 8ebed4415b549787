// ASVAL-History-Summary (vkDestroyDevice): what the layer skipped is said, with how often and why.
#include <catch2/catch_test_macros.hpp>

#include <string>

#include "device_state.h"
#include "history_host.h"
#include "reporter.h"
#include "temp_report.h"

namespace asval {
namespace {

TEST_CASE("history summary unit: checks skipped for unknown state are counted in ASVAL-History-Summary") {
  asval_test_common::TempReport file;
  {
    ReportSettings settings;
    settings.report_file = file.path;
    settings.report_info = true;
    Reporter reporter(settings);
    DeviceState state;
    ReportHistorySummary(state, reporter, VK_NULL_HANDLE);
    CHECK(file.Lines().empty());  // nothing skipped, nothing said
    state.checks_skipped_unknown_state = 3;
    ReportHistorySummary(state, reporter, VK_NULL_HANDLE);
  }
  const std::vector<std::string> lines = file.Lines();
  REQUIRE(lines.size() == 1);
  CHECK(lines[0].find("ASVAL-History-Summary") != std::string::npos);
  CHECK(lines[0].find("3 checks were skipped because the state they need was unknown") != std::string::npos);
}

}  // namespace
}  // namespace asval
