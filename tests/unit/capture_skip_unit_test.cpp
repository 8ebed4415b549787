// Issue 26, item 3: why a build info that a rule needed was not captured. Each reason is counted on its own
// (CaptureCounters, capture_skip.h) and named in ASVAL-History-Summary, in its text and in its JSON line's
// "capture_skipped" field; the plan of a geometry and the host capture say which reason stopped an info. The
// reasons a device reaches through the loader are tested in tests/integration (capture_budget_test.cpp,
// hostile_input_test.cpp, failure_injection_test.cpp).
#include <catch2/catch_test_macros.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "asval/vertex_formats.h"
#include "capture_plan.h"
#include "capture_skipped.h"
#include "device_state.h"
#include "history_host.h"
#include "history_test_builds.h"
#include "host_capture.h"
#include "reporter.h"
#include "temp_report.h"

namespace asval {
namespace {

using Counts = std::map<std::string, uint64_t>;

// The summary lines ReportHistorySummary writes for `state`.
std::vector<std::string> SummaryLines(const DeviceState& state) {
  asval_test_common::TempReport file;
  {
    ReportSettings settings;
    settings.report_file = file.path;
    settings.report_info = true;
    Reporter reporter(settings);
    ReportHistorySummary(state, reporter, VK_NULL_HANDLE);
  }
  return file.Lines();
}

std::string CaptureLine(const std::vector<std::string>& lines) {
  for (const std::string& line : lines) {
    if (line.find("Execution-time capture:") != std::string::npos) return line;
  }
  return "";
}

TEST_CASE("capture skip unit: the summary names each reason's count in its text and its JSON field") {
  DeviceState state;
  state.capture_counters.infos_captured = 5;
  state.capture_counters.bytes_captured = 640;
  state.capture_counters.NotCaptured(CaptureSkip::kOverBudget, 2);
  state.capture_counters.NotCaptured(CaptureSkip::kUnknownAddress);
  const std::string line = CaptureLine(SummaryLines(state));
  REQUIRE(!line.empty());
  INFO(line);
  // The text: the total, then each reason counted, by name, in the reasons' order.
  CHECK(line.find("5 build infos captured (640 bytes), 0 updates judged on their captured activity; 3 infos that a "
                  "rule needed could not be captured: over_capture_budget_mb=2 unknown_address=1 (their rules") !=
        std::string::npos);
  // The JSON field: every reason, zeros included.
  const nlohmann::json j = nlohmann::json::parse(line);
  REQUIRE(j.contains("capture_skipped"));
  CHECK(j["capture_skipped"] == nlohmann::json::parse(R"({"over_capture_budget_mb": 2, "unknown_address": 1,
      "buffer_not_copyable": 0, "geometry_not_captured": 0, "null_input": 0, "capture_memory_failed": 0,
      "allocation_failed": 0})"));
  CHECK(asval_test_common::ReadCaptureSkipped({line}).NonZero() == Counts{{"over_capture_budget_mb", 2},
                                                                           {"unknown_address", 1}});
}

TEST_CASE("capture skip unit: every reason has its own name and count") {
  DeviceState state;
  state.capture_counters.NotCaptured(CaptureSkip::kOverBudget, 1);
  state.capture_counters.NotCaptured(CaptureSkip::kUnknownAddress, 2);
  state.capture_counters.NotCaptured(CaptureSkip::kBufferNotCopyable, 3);
  state.capture_counters.NotCaptured(CaptureSkip::kGeometryNotCaptured, 4);
  state.capture_counters.NotCaptured(CaptureSkip::kNullInput, 5);
  state.capture_counters.NotCaptured(CaptureSkip::kCaptureMemoryFailed, 6);
  state.capture_counters.NotCaptured(CaptureSkip::kAllocationFailed, 7);
  CHECK(state.capture_counters.InfosNotCaptured() == 28);
  const std::string line = CaptureLine(SummaryLines(state));
  INFO(line);
  CHECK(line.find("28 infos that a rule needed could not be captured: over_capture_budget_mb=1 unknown_address=2 "
                  "buffer_not_copyable=3 geometry_not_captured=4 null_input=5 capture_memory_failed=6 "
                  "allocation_failed=7 (") != std::string::npos);
  CHECK(asval_test_common::ReadCaptureSkipped({line}).counts ==
        Counts{{"over_capture_budget_mb", 1}, {"unknown_address", 2}, {"buffer_not_copyable", 3},
               {"geometry_not_captured", 4}, {"null_input", 5}, {"capture_memory_failed", 6},
               {"allocation_failed", 7}});
}

TEST_CASE("capture skip unit: nothing skipped is said as 0, with every reason at 0 in the JSON field") {
  DeviceState state;
  state.capture_counters.infos_captured = 1;
  const std::string line = CaptureLine(SummaryLines(state));
  INFO(line);
  CHECK(line.find("; 0 infos that a rule needed could not be captured (their rules") != std::string::npos);
  const asval_test_common::CaptureSkipped skipped = asval_test_common::ReadCaptureSkipped({line});
  CHECK(skipped.lines == 1);
  CHECK(skipped.counts.size() == 7);
  CHECK(skipped.NonZero().empty());
}

TEST_CASE("capture skip unit: only a report given named counts carries them, under its field") {
  asval_test_common::TempReport file;
  {
    ReportSettings settings;
    settings.report_file = file.path;
    Reporter reporter(settings);
    const NamedCount counts[] = {{"apples", 3}, {"pears", 0}};
    reporter.Report(Severity::kWarning, "ASVAL-Test-Counts", Location("vkTest"), {}, "with counts",
                    NamedCounts{"fruit", counts, 2});
    reporter.Report(Severity::kWarning, "ASVAL-Test-Plain", Location("vkTest"), {}, "without");
  }
  const std::vector<std::string> lines = file.Lines();
  REQUIRE(lines.size() == 2);
  const nlohmann::json with = nlohmann::json::parse(lines[0]);
  const nlohmann::json without = nlohmann::json::parse(lines[1]);
  CHECK(with["fruit"] == nlohmann::json::parse(R"({"apples": 3, "pears": 0})"));
  CHECK(with["message"] == "with counts");
  CHECK(!without.contains("fruit"));
  CHECK(without.size() == with.size() - 1);
}

// ---- which reason stops a geometry's plan ----

VkAccelerationStructureGeometryKHR Triangles(VkDeviceAddress vertices) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  g.geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  g.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  g.geometry.triangles.vertexStride = 12;
  g.geometry.triangles.maxVertex = 2;
  g.geometry.triangles.indexType = VK_INDEX_TYPE_NONE_KHR;
  g.geometry.triangles.vertexData.deviceAddress = vertices;
  return g;
}

// The reason PlanCapturedGeometry gives for g (one primitive), or "planned".
std::string PlanOutcome(const VkAccelerationStructureGeometryKHR& g) {
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  CapturedGeometry out;
  std::vector<CaptureSource> sources;
  CaptureSkip why = CaptureSkip::kAllocationFailed;  // not a reason the plan gives: seen if it sets none
  if (PlanCapturedGeometry(g, range, false, &out, sources, &why)) return "planned";
  return std::string(NameOf(why));
}

TEST_CASE("capture skip unit: a geometry's plan names the kind or format it does not capture, and null inputs") {
  CHECK(PlanOutcome(Triangles(0x10000)) == "planned");
  VkAccelerationStructureGeometryKHR g = Triangles(0x10000);
  g.geometry.triangles.vertexFormat = VK_FORMAT_D32_SFLOAT;  // no vertex format: the builder does not decode it
  REQUIRE(!VertexFormatFacts(VK_FORMAT_D32_SFLOAT).decodable);
  CHECK(PlanOutcome(g) == "geometry_not_captured");
  g = Triangles(0x10000);
  g.geometry.triangles.indexType = static_cast<VkIndexType>(77);  // no index type the builder reads
  CHECK(PlanOutcome(g) == "geometry_not_captured");
  g = Triangles(0x10000);
  g.geometryType = static_cast<VkGeometryTypeKHR>(1000999000);  // a geometry type newer than the layer
  CHECK(PlanOutcome(g) == "geometry_not_captured");
  CHECK(PlanOutcome(Triangles(0)) == "null_input");  // vertices at address 0 with a primitive to read
  g = Triangles(0x10000);
  g.geometry.triangles.indexType = VK_INDEX_TYPE_UINT32;  // indexed, index data at 0
  CHECK(PlanOutcome(g) == "null_input");
  VkAccelerationStructureGeometryKHR aabbs{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  aabbs.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  aabbs.geometry.aabbs.stride = 24;
  CHECK(PlanOutcome(aabbs) == "null_input");
  VkAccelerationStructureGeometryKHR instances{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  instances.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  CHECK(PlanOutcome(instances) == "null_input");
}

// ---- the host capture (vkBuildAccelerationStructuresKHR) ----

TEST_CASE("capture skip unit: host builds count each info not captured under its reason") {
  // Two triangles, 6 vertices of R32G32B32_SFLOAT in host memory (72 bytes read).
  std::vector<float> vertices(18, 0.0f);
  const auto host_build = [&](VkBuildAccelerationStructureFlagsKHR extra) {
    test::Build b(reinterpret_cast<VkAccelerationStructureKHR>(uintptr_t{0x1000}), {2},
                  VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | extra);
    b.geometries[0].geometry.triangles.vertexData.hostAddress = vertices.data();
    b.geometries[0].geometry.triangles.vertexStride = 12;
    b.geometries[0].geometry.triangles.maxVertex = 5;
    b.geometries[0].geometry.triangles.indexType = VK_INDEX_TYPE_NONE_KHR;
    return b;
  };
  CaptureCounters counters;
  const auto capture = [&](const test::Build& b, VkDeviceSize budget) {
    return CaptureHostBuildInputs(1, &b.info, &b.range_pointer, budget, counters);
  };
  const auto not_captured = [&] {
    Counts out;
    for (std::size_t r = 0; r < kCaptureSkipCount; ++r) {
      if (const uint64_t n = counters.NotCapturedFor(static_cast<CaptureSkip>(r))) {
        out[std::string(NameOf(static_cast<CaptureSkip>(r)))] = n;
      }
    }
    return out;
  };

  capture(host_build(0), 1024);  // captured: the twin
  CHECK(counters.infos_captured == 1);
  CHECK(not_captured().empty());

  capture(host_build(0), 71);  // 72 bytes, one over the budget
  CHECK(not_captured() == Counts{{"over_capture_budget_mb", 1}});

  capture(host_build(VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV), 1024);  // motion: not captured yet
  CHECK(not_captured() == Counts{{"over_capture_budget_mb", 1}, {"geometry_not_captured", 1}});

  test::Build no_geometries = host_build(0);
  no_geometries.info.pGeometries = nullptr;  // geometryCount 1, and no geometry to read
  capture(no_geometries, 1024);
  test::Build null_vertices = host_build(0);
  null_vertices.geometries[0].geometry.triangles.vertexData.hostAddress = nullptr;
  capture(null_vertices, 1024);
  CHECK(not_captured() ==
        Counts{{"over_capture_budget_mb", 1}, {"geometry_not_captured", 1}, {"null_input", 2}});
  CHECK(counters.infos_captured == 1);
  CHECK(counters.InfosNotCaptured() == 4);
}

}  // namespace
}  // namespace asval
