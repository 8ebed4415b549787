// Failure paths (issue 14) without a driver: the test hook's text (ASVAL_TEST_FAIL, failure_injection.h) and its
// counting, then what the layer's state does when its allocation fails where no lavapipe run can reach: host
// commands (lavapipe has none), a submission's apply and its undo, and the shadow records of the state tracker.
// Each failure must end in "skipped and counted" (FailureCounters), never in a finding built on lost state.
#include <catch2/catch_test_macros.hpp>

#include <string>
#include <vector>

#include "build_command.h"
#include "failure_injection.h"
#include "history_apply.h"
#include "history_host.h"
#include "history_recorder.h"
#include "history_test_builds.h"
#include "layer_settings.h"
#include "state_tracker.h"
#include "submission.h"
#include "temp_report.h"
#include "update_rules.h"
#include "vk_dispatch_table.h"

namespace asval {
namespace {

using test::Build;

// ---- the text --------------------------------------------------------------------------------------------------

std::vector<FailSpec> Parsed(const char* text) {
  std::vector<FailSpec> specs;
  std::string error;
  INFO(text);
  REQUIRE(ParseFailSpecs(text, &specs, &error));
  CHECK(error.empty());
  return specs;
}

std::string Rejected(const char* text) {
  std::vector<FailSpec> specs{FailSpec{}};
  std::string error;
  INFO(text);
  CHECK_FALSE(ParseFailSpecs(text, &specs, &error));
  CHECK(specs.empty());  // never half applied
  return error;
}

TEST_CASE("failure injection unit: ASVAL_TEST_FAIL entries are point:nth[:count], comma-separated") {
  CHECK(Parsed("").empty());
  const std::vector<FailSpec> one = Parsed("state_record:3");
  REQUIRE(one.size() == 1);
  CHECK(one[0].sites == FailSiteBit(FailSite::kRecording));
  CHECK(one[0].nth == 3);
  CHECK(one[0].count == 1);  // count defaults to one failure

  const std::vector<FailSpec> two = Parsed("capture_memory:1:4,inserted_fence:2");
  REQUIRE(two.size() == 2);
  CHECK(two[0].sites == FailSiteBit(FailSite::kCaptureMemory));
  CHECK(two[0].nth == 1);
  CHECK(two[0].count == 4);
  CHECK(two[1].sites == FailSiteBit(FailSite::kLayerFence));
  CHECK(two[1].nth == 2);

  // Umbrella points name several sites.
  const uint32_t state = Parsed("state_alloc:1")[0].sites;
  for (FailSite site : {FailSite::kObjectRecord, FailSite::kStructureRecord, FailSite::kRecording, FailSite::kHostOps,
                        FailSite::kApply, FailSite::kCaptureRecord}) {
    CHECK((state & FailSiteBit(site)) != 0);
  }
  CHECK((state & FailSiteBit(FailSite::kCaptureMemory)) == 0);
  CHECK((state & FailSiteBit(FailSite::kLayerFence)) == 0);
  CHECK(Parsed("state_object:1")[0].sites ==
        (FailSiteBit(FailSite::kObjectRecord) | FailSiteBit(FailSite::kStructureRecord)));
  CHECK(Parsed("inserted_commands:1")[0].sites ==
        (FailSiteBit(FailSite::kLayerFence) | FailSiteBit(FailSite::kReducePipeline)));
}

TEST_CASE("failure injection unit: malformed ASVAL_TEST_FAIL text is rejected whole, with the reason") {
  CHECK(Rejected("state_record").find("no ':<nth>'") != std::string::npos);
  CHECK(Rejected("no_such_point:1").find("unknown point 'no_such_point'") != std::string::npos);
  CHECK(Rejected("state_record:0").find("from 1") != std::string::npos);  // 1-based
  CHECK(Rejected("state_record:x").find("from 1") != std::string::npos);
  CHECK(Rejected("state_record:1:0").find("from 1") != std::string::npos);
  CHECK(Rejected("state_record:1:2:3").find("from 1") != std::string::npos);
  CHECK(Rejected("state_record:-1").find("from 1") != std::string::npos);
  CHECK(Rejected("state_record:1,").find("empty entry") != std::string::npos);
  CHECK(Rejected(",state_record:1").find("empty entry") != std::string::npos);
  // One bad entry rejects the good ones with it.
  CHECK(Rejected("state_record:1,capture_memory:").find("from 1") != std::string::npos);
}

// Arms the process's injector for one test (after any DeviceState was made: making one re-reads the environment)
// and disarms it at the end.
struct Armed {
  explicit Armed(const char* text) { g_failure_injector.Arm(Parsed(text)); }
  ~Armed() { g_failure_injector.Arm({}); }
};

TEST_CASE("failure injection unit: the nth hit of a point and the count - 1 after it fail, each entry on its own") {
  {
    Armed armed("state_record:2:2");
    std::vector<bool> fails;
    for (int k = 0; k < 5; ++k) fails.push_back(InjectedFailure(FailSite::kRecording));
    CHECK(fails == std::vector<bool>{false, true, true, false, false});
    CHECK_FALSE(InjectedFailure(FailSite::kApply));  // another site: not counted, never fails
  }
  {
    // An umbrella counts every site it names; a narrower entry counts its own hits only.
    Armed armed("state_alloc:3,state_apply:1");
    CHECK(InjectedFailure(FailSite::kApply));          // state_alloc hit 1, state_apply hit 1: fails
    CHECK_FALSE(InjectedFailure(FailSite::kRecording));  // state_alloc hit 2
    CHECK(InjectedFailure(FailSite::kObjectRecord));     // state_alloc hit 3
    CHECK_FALSE(InjectedFailure(FailSite::kApply));      // state_alloc hit 4, state_apply hit 2
  }
  CHECK_FALSE(g_failure_injector.armed());  // disarmed: one relaxed load
  CHECK_FALSE(InjectedFailure(FailSite::kRecording));
  bool threw = false;
  {
    Armed armed("state_object:1");
    try {
      InjectBadAlloc(FailSite::kObjectRecord);
    } catch (const std::bad_alloc&) {
      threw = true;  // as a real allocation failure
    }
  }
  CHECK(threw);
}

// ---- the state under failures ------------------------------------------------------------------------------------

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

constexpr uint32_t kAll = kCheckHistory | kCheckCopies;
constexpr VkBuildAccelerationStructureFlagsKHR kStatic = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
const VkDeviceMemory kMemory = Fake<VkDeviceMemory>(1);

// A device with host commands and structures a, b on buffers of one memory (made before any test arms the hook).
struct World {
  DeviceState state;
  DeviceDispatchTable dispatch{};
  VkAccelerationStructureKHR a = Fake<VkAccelerationStructureKHR>(10);
  VkAccelerationStructureKHR b = Fake<VkAccelerationStructureKHR>(11);

  World() {
    state.features.acceleration_structure = true;
    state.features.acceleration_structure_host_commands = true;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, 1 << 24, 0};
    RecordAllocateMemory(state, alloc, kMemory);
    Structure(a, Fake<VkBuffer>(2), 0);
    Structure(b, Fake<VkBuffer>(3), 1 << 20);
  }
  void Structure(VkAccelerationStructureKHR as, VkBuffer buffer, VkDeviceSize memory_offset) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = 1 << 16;
    info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
    RecordCreateBuffer(state, info, buffer);
    RecordBindBufferMemory(state, dispatch, Fake<VkDevice>(1), buffer, kMemory, memory_offset);
    VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    create.buffer = buffer;
    create.size = 1 << 16;
    create.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    RecordCreateAccelerationStructure(state, dispatch, Fake<VkDevice>(1), create, as);
  }
  HistoryKind Kind(VkAccelerationStructureKHR as) {
    auto lock = state.history.store.Lock();
    return state.history.store.Get(as).kind;
  }
  const FailureCounters& failures() const { return state.failures(); }
  uint64_t HistorySkips() const { return state.history.store.rules_skipped_unknown_history.load(); }
};

// The host build of `build`, validated then finished as the hook does (vkBuildAccelerationStructuresKHR): true when
// a finding was reported (the reporter counts errors).
bool HostBuild(World& w, Reporter& reporter, const Build& build) {
  BuildCommand host{BuildCommandKind::kHostBuild, "vkBuildAccelerationStructuresKHR"};
  host.info_count = 1;
  host.infos = &build.info;
  host.ranges = &build.range_pointer;
  const uint64_t errors = reporter.ErrorCount();
  ValidateBuildHistory(CheckContext{w.state, reporter, kAll}, host);
  FinishHostOps(w.state, HostBuildOps(1, &build.info, &build.range_pointer), VK_NULL_HANDLE, VK_SUCCESS);
  return reporter.ErrorCount() != errors;
}

TEST_CASE("failure injection unit: a host update whose operations could not be built for its checks is skipped") {
  // Twin: a host update of a structure built without ALLOW_UPDATE is reported (03667).
  {
    World w;
    Reporter reporter(ReportSettings{});
    CHECK_FALSE(HostBuild(w, reporter, Build(w.a, {1}, kStatic)));
    CHECK(HostBuild(w, reporter, Build(w.a, {1}, kStatic, w.a)));
  }
  World w;
  Reporter reporter(ReportSettings{});
  CHECK_FALSE(HostBuild(w, reporter, Build(w.a, {1}, kStatic)));
  // Counted from here (arming starts the counts): hit 1 is the update's batch for its checks.
  Armed armed("state_host:1");
  CHECK_FALSE(HostBuild(w, reporter, Build(w.a, {1}, kStatic, w.a)));  // skipped, not reported
  CHECK(w.HistorySkips() == 1);                                       // its one history check, counted
  CHECK(w.failures().allocation_failures == 1);
  CHECK(w.failures().host_commands_lost == 0);  // its history was applied (hit 2 did not fail)
  CHECK(w.Kind(w.a) == HistoryKind::kBuilt);
}

TEST_CASE("failure injection unit: a host command whose operations could not be built for its history makes every "
          "structure unknown") {
  World w;
  Reporter reporter(ReportSettings{});
  // state_host hit 2 is the build's batch for its history: lost, so after it ran nothing is known.
  Armed armed("state_host:2");
  CHECK_FALSE(HostBuild(w, reporter, Build(w.a, {1}, kStatic)));
  CHECK(w.failures().allocation_failures == 1);
  CHECK(w.failures().host_commands_lost == 1);
  CHECK(w.failures().structures_made_unknown == 2);  // a and b: the live structures
  CHECK(w.Kind(w.a) == HistoryKind::kUnknown);
  CHECK(w.Kind(w.b) == HistoryKind::kUnknown);
  // The invalid update of it is not reported (its history is unknown): skipped, counted.
  CHECK_FALSE(HostBuild(w, reporter, Build(w.a, {1}, kStatic, w.a)));
  CHECK(w.HistorySkips() == 1);
}

TEST_CASE("failure injection unit: a host command's apply failing makes every structure unknown, never half known") {
  World w;
  Reporter reporter(ReportSettings{});
  Armed armed("state_apply:1");
  CHECK_FALSE(HostBuild(w, reporter, Build(w.a, {1}, kStatic)));
  CHECK(w.failures().allocation_failures == 1);
  CHECK(w.failures().host_commands_lost == 1);
  CHECK(w.failures().structures_made_unknown == 2);
  CHECK(w.Kind(w.a) == HistoryKind::kUnknown);
  CHECK(w.Kind(w.b) == HistoryKind::kUnknown);
}

void RecordAlone(DeviceState& state, VkCommandBuffer cb, const Build& build) {
  state.command_buffers.Reset(cb);
  RecordCmdBuild(state, cb, OpCommand::kCmdBuild, 1, &build.info, &build.range_pointer);
  state.command_buffers.End(cb);
}

// Submits cb as the queue hook does, checking each operation with the update rules; returns the findings' count.
std::size_t Submit(World& w, VkCommandBuffer cb, bool undo = false) {
  HistoryFindings findings;
  {
    HistorySubmission submission(w.state);
    const HistoryCheckSite site{Location("vkQueueSubmit"), cb, true};
    submission.Apply(cb, [&](const HistoryStore& store, const OpBatch& batch, const AsOp& op) {
      CheckOpHistory(w.state, store, kAll, batch, op, site, findings);
    });
    submission.EndApply();
    if (undo) submission.Undo();
  }
  return findings.list().size();
}

TEST_CASE("failure injection unit: a submission whose apply failed leaves every structure unknown, even if undone") {
  World w;
  const VkCommandBuffer build = Fake<VkCommandBuffer>(100), update = Fake<VkCommandBuffer>(101);
  const VkCommandBuffer cbs[] = {build, update};
  w.state.command_buffers.CreatePool(Fake<VkCommandPool>(50), 0);
  w.state.command_buffers.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr,
                                                               Fake<VkCommandPool>(50), VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                                               2},
                                   cbs);
  const Build static_build(w.a, {1}, kStatic), bad_update(w.a, {1}, kStatic, w.a);
  RecordAlone(w.state, build, static_build);
  RecordAlone(w.state, update, bad_update);
  Armed armed("state_apply:1");
  // The build's apply fails: checked first (nothing to report), applied never; the driver then rejects the
  // submission (undo): what was made unknown stays unknown.
  CHECK(Submit(w, build, true) == 0);
  CHECK(w.failures().submissions_unknown == 1);
  CHECK(w.failures().operations_unchecked == 0);
  CHECK(w.failures().structures_made_unknown == 2);
  CHECK(w.Kind(w.a) == HistoryKind::kUnknown);
  // The invalid update (its source built without ALLOW_UPDATE, had the build been known) is skipped, counted.
  CHECK(Submit(w, update) == 0);
  CHECK(w.HistorySkips() == 1);
}

TEST_CASE("failure injection unit: a command buffer recorded with a lost operation is unknown when submitted") {
  World w;
  const VkCommandBuffer build = Fake<VkCommandBuffer>(100), update = Fake<VkCommandBuffer>(101);
  const VkCommandBuffer cbs[] = {build, update};
  w.state.command_buffers.CreatePool(Fake<VkCommandPool>(50), 0);
  w.state.command_buffers.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr,
                                                               Fake<VkCommandPool>(50), VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                                               2},
                                   cbs);
  const Build static_build(w.a, {1}, kStatic), bad_update(w.a, {1}, kStatic, w.a);
  {
    Armed armed("state_record:1");  // the build's append
    RecordAlone(w.state, build, static_build);
  }
  RecordAlone(w.state, update, bad_update);
  CHECK(w.failures().recordings_lost == 1);
  CHECK(Submit(w, build) == 0);
  CHECK(w.Kind(w.a) == HistoryKind::kUnknown);
  CHECK(Submit(w, update) == 0);  // skipped: a's history is unknown
  CHECK(w.HistorySkips() == 1);
  // Twin: recorded again without the failure, the same two submissions report the update.
  RecordAlone(w.state, build, static_build);
  CHECK(Submit(w, build) == 0);
  CHECK(Submit(w, update) == 1);
}

TEST_CASE("failure injection unit: shadow records that could not be made leave their objects unknown") {
  World w;
  {
    Armed armed("state_object:1");  // the buffer's record
    w.Structure(Fake<VkAccelerationStructureKHR>(12), Fake<VkBuffer>(4), 2 << 20);
  }
  CHECK(w.failures().objects_untracked == 1);
  CHECK_FALSE(w.state.buffers.contains(Fake<VkBuffer>(4)));  // unknown, not a record saying otherwise
  CHECK(w.state.acceleration_structures.contains(Fake<VkAccelerationStructureKHR>(12)));
  {
    Armed armed("state_object:2");  // buffer 5's binding: forgotten rather than left unbound
    w.Structure(Fake<VkAccelerationStructureKHR>(13), Fake<VkBuffer>(5), 3 << 20);
  }
  CHECK(w.failures().objects_untracked == 2);
  CHECK_FALSE(w.state.buffers.contains(Fake<VkBuffer>(5)));
  {
    Armed armed("state_structure:1");
    w.Structure(Fake<VkAccelerationStructureKHR>(14), Fake<VkBuffer>(6), 4 << 20);
  }
  CHECK(w.failures().objects_untracked == 3);
  CHECK(w.state.buffers.contains(Fake<VkBuffer>(6)));
  CHECK_FALSE(w.state.acceleration_structures.contains(Fake<VkAccelerationStructureKHR>(14)));
  // An update of the unknown structure is skipped and counted, not reported as never built.
  Reporter reporter(ReportSettings{});
  const Build update(Fake<VkAccelerationStructureKHR>(14), {1}, kStatic, Fake<VkAccelerationStructureKHR>(14));
  CHECK_FALSE(HostBuild(w, reporter, update));
  CHECK(w.HistorySkips() == 1);
  CHECK(w.failures().allocation_failures == 3);
}

TEST_CASE("failure injection unit: ASVAL-History-Summary says what the failures skipped") {
  World w;
  Reporter reporter(ReportSettings{});
  {
    Armed armed("state_host:2");
    HostBuild(w, reporter, Build(w.a, {1}, kStatic));
  }
  asval_test_common::TempReport file;
  {
    ReportSettings settings;
    settings.report_file = file.path;
    settings.report_info = true;
    Reporter summary(settings);
    ReportHistorySummary(w.state, summary, VK_NULL_HANDLE);
  }
  bool said = false;
  for (const std::string& line : file.Lines()) {
    said |= line.find("ASVAL-History-Summary") != std::string::npos &&
            line.find("could not allocate 1 times (0 objects left untracked, 0 command-buffer recordings lost, 1 host "
                      "commands' operations lost, 0 submissions whose history could not be applied with 0 operations "
                      "left unchecked, 2 structures' histories made unknown") != std::string::npos;
  }
  CHECK(said);
}

// An app callback whose own allocation fails: the message is lost, counted, and nothing is thrown into the call.
VKAPI_ATTR VkBool32 VKAPI_CALL ThrowingCallback(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                                const VkDebugUtilsMessengerCallbackDataEXT*, void*) {
  throw std::bad_alloc();
}

TEST_CASE("failure injection unit: a message that could not be delivered is counted and said, never thrown") {
  asval_test_common::TempReport file;
  {
    ReportSettings settings;
    settings.report_file = file.path;
    settings.report_info = true;
    Reporter reporter(settings);
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;  // the summary (info) is not sent there
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    info.pfnUserCallback = &ThrowingCallback;
    reporter.AddMessenger(Fake<VkDebugUtilsMessengerEXT>(1), info);
    bool skip = true;
    CHECK_NOTHROW(skip = reporter.Report(Severity::kError, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667",
                                         Location("vkQueueSubmit"), {}, "a finding"));
    CHECK_FALSE(skip);
    CHECK(reporter.ReportsLost() == 1);
    World w;  // nothing else failed: the summary says only the lost message
    ReportHistorySummary(w.state, reporter, VK_NULL_HANDLE);
  }
  bool said = false;
  for (const std::string& line : file.Lines()) {
    said |= line.find("could not allocate 0 times") != std::string::npos &&
            line.find("; 1 messages could not be built.") != std::string::npos;
  }
  CHECK(said);
}

}  // namespace
}  // namespace asval
