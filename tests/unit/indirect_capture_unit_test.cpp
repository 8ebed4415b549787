// The rules an indirect build's captured range infos are judged by (ppMaxPrimitiveCounts-03653; for updates,
// primitiveCount-03769), at unit level on captured bytes: neither lavapipe nor the H200 builds indirectly, so no
// capture runs through a driver. The log is made by hand as layer/capture would fill it (the range infos copied
// from pIndirectDeviceAddresses[i], strided).
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "history_apply.h"
#include "history_test_builds.h"
#include "indirect_rules.h"
#include "record_checks_harness.h"
#include "update_rules.h"

namespace asval::test {
namespace {

constexpr const char* kOverMaximum = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-ppMaxPrimitiveCounts-03653";
constexpr const char* kCountChanged = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-primitiveCount-03769";
constexpr VkBuildAccelerationStructureFlagsKHR kUpdatable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;

// Host memory standing in for a slab (never given back to a pool).
class HostSlabs : public CaptureSlabOwner {
 public:
  bool Take(VkDeviceSize, CaptureSlab*) override { return false; }
  void Return(const CaptureSlab&) override {}
};

// A log with one indirect info of counts.size() geometries whose range infos, `stride` bytes apart, hold
// `counts`; the command's maxima are `maxima`.
struct IndirectLog {
  IndirectLog(const std::vector<uint32_t>& counts, const std::vector<uint32_t>& maxima, uint32_t stride)
      : bytes(stride * counts.size() + sizeof(VkAccelerationStructureBuildRangeInfoKHR)),
        log(std::make_shared<CaptureLog>(std::make_shared<HostSlabs>())) {
    for (std::size_t j = 0; j < counts.size(); ++j) {
      VkAccelerationStructureBuildRangeInfoKHR range{counts[j], 0, 0, 0};
      std::memcpy(bytes.data() + j * stride, &range, sizeof(range));
    }
    log->slabs.push_back(CaptureSlab{VK_NULL_HANDLE, VK_NULL_HANDLE, bytes.data(), bytes.size()});
    CapturedInfo info;
    info.indirect = true;
    info.geometry_count = static_cast<uint32_t>(counts.size());
    info.ranges = CapturedBytes{0, 0, bytes.size(), true};
    info.indirect_stride = stride;
    log->infos.push_back(info);
    log->geometries.resize(counts.size());
    log->max_primitive_counts = maxima;
  }

  IndirectRangeCheck Check() const {
    IndirectRangeCheck check;
    check.log = log;
    check.build.command = OpCommand::kCmdBuildIndirect;
    check.build.ordinal = 1;
    return check;
  }

  std::vector<uint8_t> bytes;
  std::shared_ptr<CaptureLog> log;
};

TEST_CASE("indirect capture unit: range infos over ppMaxPrimitiveCounts are reported, within them silent",
          "[unit][capture]") {
  RecordHarness h;
  for (uint32_t stride : {16u, 32u}) {
    const IndirectLog over({3, 11, 10}, {10, 10, 10}, stride);
    CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, over.Check()); }) ==
          std::vector<std::string>{kOverMaximum});
    REQUIRE(h.texts().size() == 1);
    CHECK(h.texts()[0].find("geometry 1: primitiveCount 11 > ppMaxPrimitiveCounts[0][1] = 10") != std::string::npos);
    // The twin: every count at or below its maximum (equal included).
    const IndirectLog within({3, 10, 0}, {10, 10, 10}, stride);
    CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, within.Check()); }).empty());
  }
}

TEST_CASE("indirect capture unit: range infos the layer cannot vouch for are skipped and counted", "[unit][capture]") {
  RecordHarness h;
  IndirectLog overlapped({11}, {10}, 16);
  overlapped.log->SubmissionStarted();  // pending twice: written twice before it was read
  overlapped.log->SubmissionStarted();
  IndirectLog missing({11}, {10}, 16);
  missing.log->infos[0].ranges.present = false;  // no buffer the layer could copy from
  for (IndirectLog* log : {&overlapped, &missing}) {
    const uint64_t before = h.state().checks_skipped_unknown_state.load();
    CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, log->Check()); }).empty());
    CHECK(h.state().checks_skipped_unknown_state.load() == before + 1);
  }
}

// ---- primitiveCount-03769: an indirect update's captured counts against its source's last build ----------------

OpOrigin Origin(OpCommand command) {
  OpOrigin o;
  o.command = command;
  o.ordinal = 1;
  o.command_buffer = reinterpret_cast<VkCommandBuffer>(uintptr_t{0x20});
  return o;
}

OpBatch Direct(const Build& build) {
  OpBatch batch;
  batch.AppendBuilds(Origin(OpCommand::kCmdBuild), 1, &build.info, &build.range_pointer);
  return batch;
}

// An indirect build or update whose range infos `log` captured (as its first info), or were not captured (null).
OpBatch Indirect(const Build& build, const IndirectLog* log) {
  static constexpr uint32_t kFirstInfo = 1;  // index plus one
  OpBatch batch;
  batch.AppendBuilds(Origin(OpCommand::kCmdBuildIndirect), 1, &build.info, nullptr, log ? log->log.get() : nullptr,
                     log ? &kFirstInfo : nullptr);
  return batch;
}

// One submission as vkQueueSubmit makes it: each operation checked against the history (the update rules), then
// applied, collecting what its captures ask for at completion.
struct Submitted {
  std::vector<std::string> vuids;  // the update rules' findings at submission
  SubmissionCaptures captures;
};

Submitted Submit(DeviceState& state, const OpBatch& batch) {
  Submitted out;
  HistoryFindings findings;
  HistoryStore& store = state.history.store;
  auto lock = store.Lock();
  const HistoryCheckSite site{Location("vkQueueSubmit"), reinterpret_cast<VkCommandBuffer>(uintptr_t{0x20}), true};
  for (const AsOp& op : batch.ops()) {
    CheckOpHistory(state, store, kCheckHistory, batch, op, site, findings);
    ApplyOp(state, store, batch, op, nullptr, &out.captures);
  }
  for (const HistoryFinding& f : findings.list()) out.vuids.push_back(f.vuid);
  return out;
}

// The update's check, run as the submission's completion runs it; the VUIDs reported.
std::vector<std::string> Complete(RecordHarness& h, const Submitted& submitted) {
  if (submitted.captures.indirect_checks.size() != 1) {
    return {std::to_string(submitted.captures.indirect_checks.size()) + " indirect checks, not 1"};
  }
  return h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, submitted.captures.indirect_checks[0]); });
}

constexpr uint32_t kRoomy = 100;  // a maximum no count here reaches: 03653 stays silent

TEST_CASE("indirect capture unit: an indirect update whose captured counts differ from its source's build fires "
          "primitiveCount-03769, the same counts stay silent",
          "[unit][capture][history]") {
  RecordHarness h;
  const VkAccelerationStructureKHR a = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  const Build source(a, {3, 4}, kUpdatable);
  REQUIRE(Submit(h.state(), Direct(source)).vuids.empty());
  const Build update(a, {0, 0}, kUpdatable, a);  // the counts the app wrote on the host play no part
  const uint64_t skipped = h.state().checks_skipped_unknown_state.load();

  // Geometry 1 read 5 primitives where the source was built with 4.
  const IndirectLog changed({3, 5}, {kRoomy, kRoomy}, 16);
  const Submitted submitted = Submit(h.state(), Indirect(update, &changed));
  CHECK(submitted.vuids.empty());  // nothing to say at submission: the counts are on the device
  CHECK(Complete(h, submitted) == std::vector<std::string>{kCountChanged});
  REQUIRE(h.texts().size() == 1);
  CHECK(h.texts()[0].find("geometry 1: primitiveCount 5, but the source's build had 4") != std::string::npos);
  CHECK(h.texts()[0].find("geometry 0") == std::string::npos);

  // The twin: the source's own counts.
  const IndirectLog same({3, 4}, {kRoomy, kRoomy}, 16);
  const Submitted twin = Submit(h.state(), Indirect(update, &same));
  CHECK(twin.vuids.empty());
  CHECK(Complete(h, twin).empty());
  // Every comparison was made: none skipped, at submission or completion.
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped);
}

TEST_CASE("indirect capture unit: an indirect update that differs in another parameter is reported at submission, "
          "its captured counts at completion",
          "[unit][capture][history]") {
  RecordHarness h;
  const VkAccelerationStructureKHR a = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  REQUIRE(Submit(h.state(), Direct(Build(a, {3, 4}, kUpdatable))).vuids.empty());
  Build update(a, {0, 0}, kUpdatable, a);
  update.geometries[1].geometry.triangles.vertexFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  const uint64_t skipped = h.state().checks_skipped_unknown_state.load();
  const IndirectLog changed({3, 5}, {kRoomy, kRoomy}, 16);
  const Submitted submitted = Submit(h.state(), Indirect(update, &changed));
  CHECK(submitted.vuids == std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03763"});
  CHECK(Complete(h, submitted) == std::vector<std::string>{kCountChanged});
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped);  // each count compared once, none skipped
}

TEST_CASE("indirect capture unit: an indirect update is compared with its source's build as it was when submitted",
          "[unit][capture][history]") {
  RecordHarness h;
  const VkAccelerationStructureKHR a = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  const VkAccelerationStructureKHR b = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  REQUIRE(Submit(h.state(), Direct(Build(a, {7}, kUpdatable))).vuids.empty());
  const IndirectLog seven({7}, {kRoomy}, 16);
  const Submitted update = Submit(h.state(), Indirect(Build(b, {0}, kUpdatable, a), &seven));
  // A is rebuilt with 8 primitives by a later submission before the update's completion is processed: the update
  // read 7 primitives, as A's build before it had.
  REQUIRE(Submit(h.state(), Direct(Build(a, {8}, kUpdatable))).vuids.empty());
  CHECK(Complete(h, update).empty());
  // And the other way round: 8 captured, against the 7 that A held when the update was submitted.
  REQUIRE(Submit(h.state(), Direct(Build(a, {7}, kUpdatable))).vuids.empty());
  const IndirectLog eight({8}, {kRoomy}, 16);
  const Submitted later = Submit(h.state(), Indirect(Build(b, {0}, kUpdatable, a), &eight));
  REQUIRE(Submit(h.state(), Direct(Build(a, {8}, kUpdatable))).vuids.empty());
  CHECK(Complete(h, later) == std::vector<std::string>{kCountChanged});
}

TEST_CASE("indirect capture unit: an indirect update of a source built indirectly has unknown source counts: "
          "skipped and counted once per geometry, nothing reported",
          "[unit][capture][history]") {
  RecordHarness h;
  const VkAccelerationStructureKHR a = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  // The source's own ranges were not captured either: its counts stayed on the device.
  REQUIRE(Submit(h.state(), Indirect(Build(a, {3, 4}, kUpdatable), nullptr)).vuids.empty());
  const uint64_t skipped = h.state().checks_skipped_unknown_state.load();
  const IndirectLog different({9, 9}, {kRoomy, kRoomy}, 16);
  const Submitted update = Submit(h.state(), Indirect(Build(a, {0, 0}, kUpdatable, a), &different));
  CHECK(update.vuids.empty());
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped);  // not counted at submission ...
  CHECK(Complete(h, update).empty());
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped + 2);  // ... but once per geometry at completion
}

TEST_CASE("indirect capture unit: an indirect update whose captured ranges cannot be vouched for counts each "
          "comparison it skips",
          "[unit][capture][history]") {
  RecordHarness h;
  const VkAccelerationStructureKHR a = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  REQUIRE(Submit(h.state(), Direct(Build(a, {3, 4}, kUpdatable))).vuids.empty());
  IndirectLog overlapped({9, 9}, {kRoomy, kRoomy}, 16);
  overlapped.log->SubmissionStarted();  // pending twice: written twice before it was read
  overlapped.log->SubmissionStarted();
  const uint64_t skipped = h.state().checks_skipped_unknown_state.load();
  const Submitted update = Submit(h.state(), Indirect(Build(a, {0, 0}, kUpdatable, a), &overlapped));
  CHECK(update.vuids.empty());
  CHECK(Complete(h, update).empty());
  // The maximum (03653) once, and each of the two counts 03769 would have compared.
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped + 3);
}

}  // namespace
}  // namespace asval::test
