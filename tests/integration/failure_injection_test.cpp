// Failure paths (issue 14): when the layer's own allocation, its capture memory or its own Vulkan objects fail,
// the check that needed them is skipped and counted, the app's calls go through with their own results, and
// ASVAL-History-Summary (here read from the JSON report, which carries the same messages) says what was skipped.
// The failures are injected by ASVAL_TEST_FAIL (layer/state/failure_injection.h), read when the device is created.
//
// Every test runs one program twice, without and with the failure: a structure with two triangles is built
// (capture on: the build's activity is kept for its updates), then updated after a vkCmdFillBuffer wrote a NaN over
// triangle 1's second vertex, which makes it inactive: pInfos-03664, reported once the update's submission
// completed. Then the structure's serialization size is queried, as the app's own evidence that its build and
// update happened. Every call is submitted and waited for (vkQueueWaitIdle, so that submissions carry no fence of
// the app's: the layer passes its own down).
#include <catch2/catch_test_macros.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "capture_skipped.h"
#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";
constexpr const char* kSummaryId = "ASVAL-History-Summary";

// What one run of the program saw.
struct Outcome {
  VkResult build_submit = VK_RESULT_MAX_ENUM, build_wait = VK_RESULT_MAX_ENUM;
  VkResult update_submit = VK_RESULT_MAX_ENUM, update_wait = VK_RESULT_MAX_ENUM;
  VkResult query_submit = VK_RESULT_MAX_ENUM, query_wait = VK_RESULT_MAX_ENUM;
  uint64_t serialization_size = 0;
  std::vector<Message> after_update;  // messages up to the update's wait (the finding is reported in it)
  std::vector<Message> after_query;   // messages after that (none expected)
  std::vector<std::string> summary;   // the ASVAL-History-Summary messages of the JSON report
  asval_test_common::CaptureSkipped skipped;  // their infos not captured, per reason ("capture_skipped")
};

VkResult SubmitAlone(vkkit::Device& device, VkCommandBuffer cb) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  return vkQueueSubmit(device.queue(), 1, &submit, VK_NULL_HANDLE);
}

Shape Triangles() {
  Shape s;
  s.triangles = 2;
  return s;
}

// The program above, under ASVAL_TEST_FAIL=`fail` (null: none) and the extra settings.
Outcome Run(const char* fail, std::vector<std::pair<const char*, const char*>> settings = {}) {
  asval_test_common::TempReport report;
  settings.emplace_back("report_file", report.path.c_str());
  settings.emplace_back("report_flags", "error,warn,info");
  Outcome out;
  {
    // The layer reads the variable when the device is created; unset right after, so that no other test's device
    // sees it.
    if (fail) REQUIRE(setenv("ASVAL_TEST_FAIL", fail, 1) == 0);
    auto f = std::make_unique<HistoryFixture>(nullptr, settings);
    REQUIRE(unsetenv("ASVAL_TEST_FAIL") == 0);
    vkkit::Device& device = f->device();
    {
      Inputs inputs(device, VK_BUFFER_USAGE_TRANSFER_DST_BIT);  // valid triangles, written on the host
      Blas blas(device, inputs), other(device, inputs);         // `other` is never built: a live bystander
      Commands commands(device);
      QueryPool queries(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 1);

      VkCommandBuffer build = RecordWith(commands, [&](VkCommandBuffer cb) { blas.Build(cb, Triangles()); });
      out.build_submit = SubmitAlone(device, build);
      out.build_wait = vkQueueWaitIdle(device.queue());

      VkCommandBuffer update = RecordWith(commands, [&](VkCommandBuffer cb) {
        // Vertex 4's X (triangle 1's second vertex), R32G32B32_SFLOAT tightly packed.
        vkCmdFillBuffer(cb, inputs.buffer().buffer, Inputs::kVerticesOffset + 12 * 4, sizeof(uint32_t), kNan);
        InputsWritten(cb);
        blas.Update(cb, Triangles());
      });
      out.update_submit = SubmitAlone(device, update);
      out.update_wait = vkQueueWaitIdle(device.queue());
      out.after_update = f->monitor().Take();

      VkCommandBuffer query = RecordWith(commands, [&](VkCommandBuffer cb) {
        queries.Reset(cb);
        CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                           queries.handle(), 0);
      });
      out.query_submit = SubmitAlone(device, query);
      out.query_wait = vkQueueWaitIdle(device.queue());
      out.serialization_size = queries.Results(0, 1)[0];
      out.after_query = f->monitor().Take();
    }
    f->Close();  // vkDestroyDevice writes the summary
  }
  out.skipped = asval_test_common::ReadCaptureSkipped(report.Lines());
  for (const std::string& line : report.Lines()) {
    if (!nlohmann::json::accept(line)) continue;
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j.value("vuid", std::string()) == kSummaryId && j.contains("message")) {
      out.summary.push_back(j["message"].get<std::string>());
    }
  }
  return out;
}

// The numbers of the summary line that `pattern` finds (empty when no line matches).
std::vector<uint64_t> Numbers(const Outcome& o, const std::regex& pattern) {
  for (const std::string& line : o.summary) {
    std::smatch m;
    if (!std::regex_search(line, m, pattern)) continue;
    std::vector<uint64_t> numbers;
    for (std::size_t k = 1; k < m.size(); ++k) numbers.push_back(std::stoull(m[k].str()));
    return numbers;
  }
  return {};
}

// The layer's failures line: allocation failures, objects untracked, recordings lost, host commands lost,
// submissions not applied, operations unchecked, structures made unknown, commands' captures dropped,
// capture memory failures, own Vulkan objects failed, submissions' captures never read, capture checks not run.
std::vector<uint64_t> Failures(const Outcome& o) {
  static const std::regex pattern(
      R"(could not allocate (\d+) times \((\d+) objects left untracked, (\d+) command-buffer recordings lost, )"
      R"((\d+) host commands' operations lost, (\d+) submissions whose history could not be applied with (\d+) )"
      R"(operations left unchecked, (\d+) structures' histories made unknown, (\d+) commands' captures )"
      R"(dropped\); capture memory could not be had (\d+) times .*could not be made (\d+) times \((\d+) )"
      R"(submissions' captures never read, (\d+) capture checks not run)");
  return Numbers(o, pattern);
}

// The history line: checks skipped for unknown history, structures that got an unknown history.
std::vector<uint64_t> HistorySkips(const Outcome& o) {
  static const std::regex pattern(
      R"((\d+) history checks were skipped because the history they need was unknown \((\d+) structures got)");
  return Numbers(o, pattern);
}

// The capture line: infos captured, updates judged on their captured activity, infos not captured.
std::vector<uint64_t> Captured(const Outcome& o) {
  static const std::regex pattern(
      R"(Execution-time capture: (\d+) build infos captured \(\d+ bytes\), (\d+) updates judged on their )"
      R"(captured activity; (\d+) infos)");
  return Numbers(o, pattern);
}

std::string Describe(const std::vector<Message>& messages) {
  std::string text;
  for (const Message& m : messages) text += m.id_name + ": " + m.text + "\n";
  return text;
}

// The app's calls returned their own results, and the device did the same work as without the failure.
void CheckAppUnchanged(const Outcome& twin, const Outcome& failed) {
  for (VkResult r : {failed.build_submit, failed.build_wait, failed.update_submit, failed.update_wait,
                     failed.query_submit, failed.query_wait}) {
    CHECK(r == VK_SUCCESS);
  }
  CHECK(failed.serialization_size != 0);
  CHECK(failed.serialization_size == twin.serialization_size);
  INFO(Describe(failed.after_query));
  CHECK(failed.after_query.empty());
}

// The twin, without a failure: the finding is reported (so a silent run under a failure means it was skipped).
const Outcome& Twin() {
  static const Outcome twin = Run(nullptr);
  return twin;
}

TEST_CASE("failure injection: without a failure the update's activity change is reported and nothing is counted",
          "[integration][failures]") {
  const Outcome& o = Twin();
  for (VkResult r : {o.build_submit, o.build_wait, o.update_submit, o.update_wait, o.query_submit, o.query_wait}) {
    CHECK(r == VK_SUCCESS);
  }
  REQUIRE(o.after_update.size() == 1);
  CHECK(o.after_update[0].id_name == kBecameInactive);
  CHECK(o.after_update[0].text.find("primitive 1") != std::string::npos);
  CHECK(o.serialization_size != 0);
  CHECK(Failures(o).empty());      // no failure line
  CHECK(HistorySkips(o).empty());  // nothing skipped for unknown history
  // The build (ALLOW_UPDATE) and the update captured; the update judged.
  CHECK(Captured(o) == std::vector<uint64_t>{2, 1, 0});
  // Every reason an info may be skipped for is in the summary's JSON field, at 0.
  CHECK(o.skipped.lines == 1);
  CHECK(o.skipped.counts == std::map<std::string, uint64_t>{{"over_capture_budget_mb", 0},
                                                            {"unknown_address", 0},
                                                            {"buffer_not_copyable", 0},
                                                            {"geometry_not_captured", 0},
                                                            {"null_input", 0},
                                                            {"capture_memory_failed", 0},
                                                            {"allocation_failed", 0}});
}

// What the summary must say under each failure: the failure line, the history line (empty: none), the capture line,
// and the reasons of the infos not captured (those counted: the capture line's last number, by name).
struct Expected {
  std::vector<uint64_t> failures;
  std::vector<uint64_t> history;
  std::vector<uint64_t> captured;
  std::map<std::string, uint64_t> not_captured = {};
};

void CheckSkipped(const char* fail, const Expected& expected,
                  const std::vector<std::pair<const char*, const char*>>& settings = {}) {
  const Outcome failed = Run(fail, settings);
  CheckAppUnchanged(Twin(), failed);
  INFO("ASVAL_TEST_FAIL=" << fail << "\nsummary:\n" << [&] {
    std::string s;
    for (const std::string& line : failed.summary) s += line + "\n";
    return s;
  }());
  INFO("messages up to the update's wait:\n" << Describe(failed.after_update));
  CHECK(failed.after_update.empty());  // the finding that needed what was lost: skipped
  CHECK(Failures(failed) == expected.failures);
  CHECK(HistorySkips(failed) == expected.history);
  CHECK(Captured(failed) == expected.captured);
  CHECK(failed.skipped.NonZero() == expected.not_captured);
}

TEST_CASE("failure injection: a recording whose operation could not be appended is lost, its effects unknown",
          "[integration][failures]") {
  // state_record:1 is the build's append (the first recorded acceleration-structure command): the build's command
  // buffer is lost, so its submission makes both live structures unknown (2); the update of an unknown source is
  // skipped (1 history check; the structure then holds what the update built, so the property query after it is
  // judged). Both commands' inputs were still captured (the capture precedes the append); none judged.
  CheckSkipped("state_record:1", {{1, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0}, {1, 2}, {2, 0, 0}});
}

TEST_CASE("failure injection: a recording whose snapshot could not be published at vkEndCommandBuffer is lost",
          "[integration][failures]") {
  // state_record:2 is the build's command buffer's vkEndCommandBuffer (after the build's append, hit 1): the same
  // lost recording, counted once.
  CheckSkipped("state_record:2", {{1, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0}, {1, 2}, {2, 0, 0}});
}

TEST_CASE("failure injection: a submission whose history apply failed makes every structure unknown",
          "[integration][failures]") {
  // state_apply:1 is the build's operation applied at its submission (checked first: 0 unchecked): both live
  // structures made unknown (2, counted on the failures line too); then as above (1 history check skipped).
  CheckSkipped("state_apply:1", {{1, 0, 0, 0, 1, 0, 2, 0, 0, 0, 0, 0}, {1, 2}, {2, 0, 0}});
}

TEST_CASE("failure injection: a structure whose shadow record could not be made is unknown to the layer",
          "[integration][failures]") {
  // state_structure:1 is the first structure created, the one built and updated: untracked (1). Its update and
  // its property query read a structure the layer does not know: 2 history checks skipped, no history made
  // unknown (it has none).
  CheckSkipped("state_structure:1", {{1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, {2, 0}, {2, 0, 0}});
}

TEST_CASE("failure injection: capture memory that could not be had leaves the build's activity unknown",
          "[integration][failures]") {
  // capture_memory:1 is the first capture slab, for the build: the build is not captured (1), the update is (its
  // slab is the second); the update's source activity is unknown, so it is not judged. No history is unknown.
  CheckSkipped("capture_memory:1",
               {{0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0}, {}, {1, 0, 1}, {{"capture_memory_failed", 1}}});
}

TEST_CASE("failure injection: the capture's own bookkeeping failing drops the command's captures",
          "[integration][failures]") {
  // capture_alloc:1 is the build command's capture: dropped (1 command, its 1 info not captured).
  CheckSkipped("capture_alloc:1", {{1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0}, {}, {1, 0, 1}, {{"allocation_failed", 1}}});
}

TEST_CASE("failure injection: without a fence of the layer's, a submission's captures are never read",
          "[integration][failures]") {
  // inserted_fence:1 is the fence the layer passes down with the build's submission (the app gives none): the
  // build's captured bytes are never read (1 submission, no check of its own), so the update is not judged.
  CheckSkipped("inserted_fence:1", {{0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 0}, {}, {2, 0, 0}});
}

TEST_CASE("failure injection: the reducing pipeline failing makes the capture copy instead, nothing skipped",
          "[integration][failures]") {
  // capture_method reduce (lavapipe's default is copy): inserted_pipeline:1 is its one pipeline, compiled at the
  // first reduced capture. The captures are copied instead and the update is judged as without the failure: the
  // finding is still reported, and the failure is counted.
  const Outcome failed = Run("inserted_pipeline:1", {{"capture_method", "reduce"}});
  CheckAppUnchanged(Twin(), failed);
  REQUIRE(failed.after_update.size() == 1);
  CHECK(failed.after_update[0].id_name == kBecameInactive);
  CHECK(Failures(failed) == std::vector<uint64_t>{0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0});
  bool said = false;
  for (const std::string& line : failed.summary) {
    said |= line.find("the reducing pipeline failed, so the captures were copied instead") != std::string::npos;
  }
  CHECK(said);
  CHECK(Captured(failed) == std::vector<uint64_t>{2, 1, 0});
}

TEST_CASE("failure injection: several failures at once are each counted", "[integration][failures]") {
  // The build's append (state_record:1) and the first capture slab (capture_memory:1): the lost recording as in
  // its own test, and the build not captured.
  CheckSkipped("state_record:1,capture_memory:1",
               {{1, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0}, {1, 2}, {1, 0, 1}, {{"capture_memory_failed", 1}}});
}

}  // namespace
}  // namespace asval_test
