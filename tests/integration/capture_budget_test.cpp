// ASVAL-Capture-Budget: capture_budget_mb bounds the bytes that one recording of a command buffer captures (here
// the setting's minimum, 1 MB = 1 MiB). Over it, a build's inputs are not captured, the rules that need them are
// skipped and counted, and a warning names the setting, once per device, when the build is recorded. A top-level
// build reads 64 bytes per instance: 20000 instances are 1,280,000 bytes, over 1 MiB; 10000 are 640,000, under
// it. The instances' references are 0 (inactive): a valid build, with nothing for lavapipe to follow.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "capture_skipped.h"
#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char* kOverBudget = "ASVAL-Capture-Budget";
constexpr VkDeviceSize kOneMiB = VkDeviceSize{1} << 20;
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);
constexpr uint32_t kOverOneMiB = 20000;
constexpr uint32_t kUnderOneMiB = 10000;
static_assert(kOverOneMiB * kInstanceBytes > kOneMiB, "one build over the budget");
static_assert(kUnderOneMiB * kInstanceBytes < kOneMiB && 2 * kUnderOneMiB * kInstanceBytes > kOneMiB,
              "one build under the budget, two over it");

// A top-level structure for up to kOverOneMiB instances and a host-written buffer of that many inactive instances.
class Scene {
 public:
  explicit Scene(vkkit::Device& device) : device_(device), tlas_(device, kOverOneMiB), commands_(device) {
    instances_ = device.CreateBuffer(kOverOneMiB * kInstanceBytes,
                                     VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    std::memset(instances_.mapped, 0, kOverOneMiB * kInstanceBytes);
  }
  ~Scene() { device_.Destroy(instances_); }
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // A recording of one top-level build per count, of that many instances. Each build waits for the structure's
  // earlier writes (an earlier build, in this recording or one submitted before it in the same batch).
  VkCommandBuffer Recording(const std::vector<uint32_t>& counts) {
    return RecordWith(commands_, [&](VkCommandBuffer cb) {
      for (uint32_t count : counts) {
        commands_.Barrier(cb);
        tlas_.Record(cb, instances_, count, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
      }
    });
  }
  Commands& commands() { return commands_; }

 private:
  vkkit::Device& device_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer instances_;
};

// Empty when the messages since the last check are exactly one ASVAL-Capture-Budget warning naming a 1 MB budget.
std::string OneBudgetWarning(Monitor& monitor) {
  const std::vector<Message> messages = monitor.Take();
  if (messages.size() == 1 && messages[0].id_name == kOverBudget &&
      messages[0].severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT &&
      messages[0].text.find("capture_budget_mb (1 MB)") != std::string::npos) {
    return "";
  }
  std::string seen = "expected one ASVAL-Capture-Budget warning, got " + std::to_string(messages.size()) + ":\n";
  for (const Message& m : messages) seen += m.id_name + ": " + m.text + "\n";
  return seen;
}

TEST_CASE("capture: a recording that captures more than capture_budget_mb is warned about, once per device",
          "[capture]") {
  // Its sizes are the bytes copied (the method pinned: auto reduces on a GPU); reduced on the device, as the
  // environment may still ask (it wins over the API), the same builds take a fraction of them.
  if (CaptureReducedRun()) SKIP("capture_method=reduce: these builds stay under the budget");
  HistoryFixture f(nullptr, {{"capture_budget_mb", "1"}, {"capture_method", "copy"}});
  Scene scene(f.device());
  // Reported when the build that crosses the budget is recorded.
  const VkCommandBuffer over = scene.Recording({kOverOneMiB});
  CHECK(OneBudgetWarning(f.monitor()) == "");
  CHECK(scene.commands().Submit(over) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");  // nothing more on execution: the skipped rules are counted
  // Once per device: another recording over the budget says nothing new.
  CHECK(scene.commands().Submit(scene.Recording({kOverOneMiB})) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture valid twin: the same recording under the default capture_budget_mb is not warned about",
          "[capture]") {
  HistoryFixture f;
  Scene scene(f.device());
  CHECK(scene.commands().Submit(scene.Recording({kOverOneMiB})) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: capture_budget_mb bounds each recording of a command buffer, not a submission", "[capture]") {
  // Its sizes are the bytes copied (the method pinned: auto reduces on a GPU); reduced on the device, as the
  // environment may still ask (it wins over the API), the same builds take a fraction of them.
  if (CaptureReducedRun()) SKIP("capture_method=reduce: these builds stay under the budget");
  HistoryFixture f(nullptr, {{"capture_budget_mb", "1"}, {"capture_method", "copy"}});
  Scene scene(f.device());
  // Two recordings under the budget each, over it together, in one submission: silent.
  const std::vector<VkCommandBuffer> both = {scene.Recording({kUnderOneMiB}), scene.Recording({kUnderOneMiB})};
  CHECK(f.monitor().Verify() == "");
  CHECK(scene.commands().Submit(both) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  // The same two builds in one recording: the second crosses the budget.
  const VkCommandBuffer one = scene.Recording({kUnderOneMiB, kUnderOneMiB});
  CHECK(OneBudgetWarning(f.monitor()) == "");
  CHECK(scene.commands().Submit(one) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: infos over capture_budget_mb are counted in ASVAL-History-Summary as over_capture_budget_mb",
          "[capture]") {
  if (CaptureReducedRun()) SKIP("capture_method=reduce: these builds stay under the budget");
  asval_test_common::TempReport report;
  {
    HistoryFixture f(nullptr, {{"capture_budget_mb", "1"},
                               {"capture_method", "copy"},
                               {"report_file", report.path.c_str()},
                               {"report_flags", "error,warn,info"}});
    {
      Scene scene(f.device());
      // One recording whose second build crosses the budget (the first is captured), one over it alone, and one
      // under it: 2 infos not captured, 2 captured.
      CHECK(scene.commands().Submit(scene.Recording({kUnderOneMiB, kUnderOneMiB})) == VK_SUCCESS);
      CHECK(scene.commands().Submit(scene.Recording({kOverOneMiB})) == VK_SUCCESS);
      CHECK(scene.commands().Submit(scene.Recording({kUnderOneMiB})) == VK_SUCCESS);
      CHECK(OneBudgetWarning(f.monitor()) == "");
    }
    f.Close();  // vkDestroyDevice writes the summary
  }
  const std::vector<std::string> lines = report.Lines();
  const asval_test_common::CaptureSkipped skipped = asval_test_common::ReadCaptureSkipped(lines);
  CHECK(skipped.lines == 1);
  CHECK(skipped.NonZero() == std::map<std::string, uint64_t>{{"over_capture_budget_mb", 2}});
  bool said = false;
  for (const std::string& line : lines) {
    said |= line.find("Execution-time capture: 2 build infos captured") != std::string::npos &&
            line.find("; 2 infos that a rule needed could not be captured: over_capture_budget_mb=2 (") !=
                std::string::npos;
  }
  CHECK(said);
}

}  // namespace
}  // namespace asval_test
