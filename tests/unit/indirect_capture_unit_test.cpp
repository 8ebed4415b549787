// The rules an indirect build's captured range infos are judged by (ppMaxPrimitiveCounts-03653; for updates,
// primitiveCount-03769; the range rules, pIndirectDeviceAddresses-03651), at unit level on captured bytes: neither
// lavapipe nor the H200 builds indirectly, so no capture runs through a driver. The log is made by hand as
// layer/capture would fill it (the range infos copied from pIndirectDeviceAddresses[i], strided; per geometry the
// facts the range rules need); what the recorder keeps is tested on its own, over a fake next dispatch table.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "capture_recorder.h"
#include "history_apply.h"
#include "history_test_builds.h"
#include "indirect_rules.h"
#include "record_checks_harness.h"
#include "update_rules.h"

namespace asval::test {
namespace {

constexpr const char* kOverMaximum = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-ppMaxPrimitiveCounts-03653";
constexpr const char* kCountChanged = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-primitiveCount-03769";
constexpr const char* kRangeInvalid = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03651";
constexpr VkBuildAccelerationStructureFlagsKHR kUpdatable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;

// Host memory standing in for a slab (never given back to a pool).
class HostSlabs : public CaptureSlabOwner {
 public:
  bool Take(VkDeviceSize, CaptureSlab*) override { return false; }
  void Return(const CaptureSlab&) override {}
};

using Range = VkAccelerationStructureBuildRangeInfoKHR;

// A captured geometry's facts as the recorder keeps them for an indirect build (range_facts set).
CapturedGeometry Facts(VkGeometryTypeKHR type) {
  CapturedGeometry g;
  g.type = type;
  g.range_facts = true;
  return g;
}

CapturedGeometry Triangles(VkFormat format, VkIndexType index_type, uint32_t max_vertex) {
  CapturedGeometry g = Facts(VK_GEOMETRY_TYPE_TRIANGLES_KHR);
  g.vertex_format = format;
  g.index_type = index_type;
  g.max_vertex = max_vertex;
  return g;
}

// Counts alone: AABB geometries, every offset 0 (valid for the range rules, which then stay silent).
std::vector<Range> CountRanges(const std::vector<uint32_t>& counts) {
  std::vector<Range> ranges;
  for (uint32_t count : counts) ranges.push_back(Range{count, 0, 0, 0});
  return ranges;
}

// A log with one indirect info of ranges.size() geometries (facts `geometries`) whose range infos, `stride` bytes
// apart, hold `ranges`; the command's maxima are `maxima`.
struct IndirectLog {
  IndirectLog(const std::vector<uint32_t>& counts, const std::vector<uint32_t>& maxima, uint32_t stride)
      : IndirectLog(CountRanges(counts),
                    std::vector<CapturedGeometry>(counts.size(), Facts(VK_GEOMETRY_TYPE_AABBS_KHR)), maxima, stride) {}

  IndirectLog(const std::vector<Range>& ranges, const std::vector<CapturedGeometry>& geometries,
              const std::vector<uint32_t>& maxima, uint32_t stride)
      : bytes(stride * ranges.size() + sizeof(Range)),
        log(std::make_shared<CaptureLog>(std::make_shared<HostSlabs>())) {
    for (std::size_t j = 0; j < ranges.size(); ++j) std::memcpy(bytes.data() + j * stride, &ranges[j], sizeof(Range));
    log->slabs.push_back(CaptureSlab{VK_NULL_HANDLE, VK_NULL_HANDLE, bytes.data(), bytes.size()});
    CapturedInfo info;
    info.indirect = true;
    info.geometry_count = static_cast<uint32_t>(ranges.size());
    info.ranges = CapturedBytes{0, 0, bytes.size(), true};
    info.indirect_stride = stride;
    log->infos.push_back(info);
    log->geometries = geometries;
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
    // The maximum (03653) once, and the one geometry's range (03651).
    CHECK(h.state().checks_skipped_unknown_state.load() == before + 2);
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
  // The maximum (03653) once, each of the two geometries' ranges (03651), and each of the two counts 03769 would
  // have compared.
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped + 5);
}

// ---- pIndirectDeviceAddresses-03651: the range rules on captured range infos ----------------------------------

// The range rules' VUIDs as 03651's findings name them: the rule's own VUID without "VUID-".
constexpr const char* kNamesARule = "(VkAccelerationStructureBuildRangeInfoKHR-";

std::size_t Occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// One broken range: geometry 1 of an info whose geometry 0 (AABBs at offset 0) is valid, so the finding must
// name the right geometry and read its range at the right stride.
struct BrokenRange {
  const char* rule;
  CapturedGeometry geometry;
  Range range;
  std::vector<std::string> findings;  // each, in full, in the message (and no other rule named)
};

std::vector<BrokenRange> BrokenRanges() {
  return {
      {"03656, 32-bit indices", Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_UINT32, 100), Range{1, 6, 0, 0},
       {"geometry 1: primitiveOffset 6 is not a multiple of the index size 4 "
        "(VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03656)"}},
      {"03656, 16-bit indices", Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_UINT16, 100), Range{1, 3, 0, 0},
       {"geometry 1: primitiveOffset 3 is not a multiple of the index size 2 "
        "(VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03656)"}},
      {"03657, 32-bit components", Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 100),
       Range{1, 6, 0, 0},
       {"geometry 1: primitiveOffset 6 is not a multiple of 4 bytes, the component size of the non-indexed "
        "vertexFormat VK_FORMAT_R32G32B32_SFLOAT (VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657)"}},
      {"03657, 16-bit components", Triangles(VK_FORMAT_R16G16B16A16_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 100),
       Range{1, 3, 0, 0},
       {"geometry 1: primitiveOffset 3 is not a multiple of 2 bytes, the component size of the non-indexed "
        "vertexFormat VK_FORMAT_R16G16B16A16_SFLOAT (VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657)"}},
      {"03657, a packed format", Triangles(VK_FORMAT_A2B10G10R10_UNORM_PACK32, VK_INDEX_TYPE_NONE_KHR, 100),
       Range{1, 2, 0, 0},
       {"geometry 1: primitiveOffset 2 is not a multiple of 4 bytes, the size of the packed format of the "
        "non-indexed vertexFormat VK_FORMAT_A2B10G10R10_UNORM_PACK32 "
        "(VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657)"}},
      {"03658", Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_UINT32, 100), Range{1, 0, 0, 8},
       {"geometry 1: transformOffset 8 is not a multiple of 16 "
        "(VkAccelerationStructureBuildRangeInfoKHR-transformOffset-03658)"}},
      {"03659", Facts(VK_GEOMETRY_TYPE_AABBS_KHR), Range{1, 4, 0, 0},
       {"geometry 1: primitiveOffset 4 is not a multiple of 8 (AABBs) "
        "(VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03659)"}},
      {"03660", Facts(VK_GEOMETRY_TYPE_INSTANCES_KHR), Range{1, 8, 0, 0},
       {"geometry 1: primitiveOffset 8 is not a multiple of 16 (instances) "
        "(VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03660)"}},
      // More vertices than maxVertex + 1 always also reads past maxVertex: 10418 never comes alone.
      {"10418 (and 10775)", Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 5), Range{3, 0, 0, 0},
       {"geometry 1: primitiveCount 3 consumes 9 vertices, more than maxVertex 5 + 1 "
        "(VkAccelerationStructureBuildRangeInfoKHR-vertexData-10418)",
        "geometry 1: firstVertex 0 + primitiveCount 3 * 3 - 1 = 8 is past maxVertex 5 "
        "(VkAccelerationStructureBuildRangeInfoKHR-None-10775)"}},
      {"10775", Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 8), Range{3, 0, 1, 0},
       {"geometry 1: firstVertex 1 + primitiveCount 3 * 3 - 1 = 9 is past maxVertex 8 "
        "(VkAccelerationStructureBuildRangeInfoKHR-None-10775)"}},
  };
}

TEST_CASE("indirect capture unit: each range rule a captured range info breaks fires pIndirectDeviceAddresses-03651, "
          "naming the geometry, the field and the rule",
          "[unit][capture][structure]") {
  RecordHarness h;
  for (const BrokenRange& c : BrokenRanges()) {
    for (uint32_t stride : {16u, 32u}) {
      INFO(c.rule << ", stride " << stride);
      const IndirectLog log({Range{1, 0, 0, 0}, c.range}, {Facts(VK_GEOMETRY_TYPE_AABBS_KHR), c.geometry},
                            {kRoomy, kRoomy}, stride);
      const uint64_t skipped = h.state().checks_skipped_unknown_state.load();
      CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, log.Check()); }) ==
            std::vector<std::string>{kRangeInvalid});
      REQUIRE(h.texts().size() == 1);
      const std::string& text = h.texts()[0];
      for (const std::string& finding : c.findings) CHECK(text.find(finding) != std::string::npos);
      CHECK(Occurrences(text, kNamesARule) == c.findings.size());
      CHECK(text.find("pIndirectDeviceAddresses[0]") != std::string::npos);
      CHECK(text.find("geometry 0") == std::string::npos);
      CHECK(h.state().checks_skipped_unknown_state.load() == skipped);
    }
  }
}

TEST_CASE("indirect capture unit: pIndirectDeviceAddresses-03651 names four findings and counts the rest",
          "[unit][capture][structure]") {
  RecordHarness h;
  const std::vector<Range> misaligned(6, Range{1, 4, 0, 0});
  const IndirectLog log(misaligned, std::vector<CapturedGeometry>(6, Facts(VK_GEOMETRY_TYPE_AABBS_KHR)),
                        std::vector<uint32_t>(6, kRoomy), 16);
  CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, log.Check()); }) ==
        std::vector<std::string>{kRangeInvalid});
  REQUIRE(h.texts().size() == 1);
  CHECK(Occurrences(h.texts()[0], kNamesARule) == 4);
  CHECK(h.texts()[0].find("geometry 3: primitiveOffset 4") != std::string::npos);
  CHECK(h.texts()[0].find("(and 2 more findings)") != std::string::npos);
}

TEST_CASE("indirect capture unit: pIndirectDeviceAddresses-03651 valid twin: captured ranges valid for every kind of "
          "geometry stay silent",
          "[unit][capture][structure]") {
  constexpr auto kSpheres = static_cast<VkGeometryTypeKHR>(1000429004);  // VK_GEOMETRY_TYPE_SPHERES_NV
  const std::vector<std::pair<CapturedGeometry, Range>> valid = {
      {Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_UINT16, 10), Range{1, 2, 0, 0}},
      // Indexed: firstVertex is judged with the indices (10774), which stay on the device.
      {Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_UINT32, 10), Range{1, 8, 50, 32}},
      // Exactly maxVertex + 1 vertices, the last one maxVertex.
      {Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 8), Range{3, 12, 0, 16}},
      {Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 11), Range{3, 4, 3, 0}},
      {Triangles(VK_FORMAT_R16G16B16A16_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 2), Range{1, 2, 0, 0}},
      {Triangles(VK_FORMAT_A2B10G10R10_UNORM_PACK32, VK_INDEX_TYPE_NONE_KHR, 2), Range{1, 4, 0, 0}},
      {Triangles(VK_FORMAT_R8G8B8A8_SNORM, VK_INDEX_TYPE_NONE_KHR, 2), Range{1, 1, 0, 0}},
      // No triangles: nothing is read, firstVertex names no vertex.
      {Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 0), Range{0, 0, 100, 0}},
      {Facts(VK_GEOMETRY_TYPE_AABBS_KHR), Range{2, 8, 0, 0}},
      {Facts(VK_GEOMETRY_TYPE_INSTANCES_KHR), Range{2, 16, 0, 0}},
      // Geometry types of newer extensions have rules of their own.
      {Facts(kSpheres), Range{1, 3, 0, 5}},
  };
  std::vector<CapturedGeometry> geometries;
  std::vector<Range> ranges;
  for (const auto& [geometry, range] : valid) {
    geometries.push_back(geometry);
    ranges.push_back(range);
  }
  RecordHarness h;
  for (uint32_t stride : {16u, 32u}) {
    INFO("stride " << stride);
    const IndirectLog log(ranges, geometries, std::vector<uint32_t>(valid.size(), kRoomy), stride);
    const uint64_t skipped = h.state().checks_skipped_unknown_state.load();
    CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, log.Check()); }).empty());
    CHECK(h.state().checks_skipped_unknown_state.load() == skipped);  // every range judged
  }
}

TEST_CASE("indirect capture unit: pIndirectDeviceAddresses-03651 skips and counts a geometry whose facts are unknown, "
          "and judges the others",
          "[unit][capture][structure]") {
  RecordHarness h;
  // Geometry 0: its facts were not kept (a null element of ppGeometries); geometry 1: a vertex format the table
  // does not describe, so 03657 has no unit to judge by (its vertex counts are judged: within maxVertex).
  CapturedGeometry unread;  // range_facts false
  unread.type = VK_GEOMETRY_TYPE_AABBS_KHR;
  const CapturedGeometry depth = Triangles(VK_FORMAT_D32_SFLOAT, VK_INDEX_TYPE_NONE_KHR, 2);
  const Range odd{1, 3, 0, 0};  // off every unit but 1

  const IndirectLog unknown({odd, odd}, {unread, depth}, {kRoomy, kRoomy}, 16);
  uint64_t skipped = h.state().checks_skipped_unknown_state.load();
  CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, unknown.Check()); }).empty());
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped + 2);

  // With a third, AABB geometry at the same offset: only it is reported.
  const IndirectLog third({odd, odd, odd}, {unread, depth, Facts(VK_GEOMETRY_TYPE_AABBS_KHR)},
                          {kRoomy, kRoomy, kRoomy}, 16);
  skipped = h.state().checks_skipped_unknown_state.load();
  CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, third.Check()); }) ==
        std::vector<std::string>{kRangeInvalid});
  REQUIRE(h.texts().size() == 1);
  CHECK(h.texts()[0].find("geometry 2: primitiveOffset 3 is not a multiple of 8 (AABBs)") != std::string::npos);
  CHECK(Occurrences(h.texts()[0], kNamesARule) == 1);
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped + 2);
}

TEST_CASE("indirect capture unit: pIndirectDeviceAddresses-03651 follows the structure family", "[unit][capture]") {
  RecordHarness h;
  const IndirectLog log({Range{1, 4, 0, 0}}, {Facts(VK_GEOMETRY_TYPE_AABBS_KHR)}, {kRoomy}, 16);
  const uint64_t skipped = h.state().checks_skipped_unknown_state.load();
  CHECK(h.RunCheck([&](const CheckContext& ctx) { CheckIndirectRanges(ctx, log.Check()); },
                   kRecordFamilies & ~uint32_t{kCheckStructure})
            .empty());
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped);  // off: not a check skipped
}

// ---- what the recorder keeps of an indirect build's geometries ------------------------------------------------

void VKAPI_CALL NoCopy(VkCommandBuffer, VkBuffer, VkBuffer, uint32_t, const VkBufferCopy*) {}
void VKAPI_CALL NoBarrier(VkCommandBuffer, VkPipelineStageFlags, VkPipelineStageFlags, VkDependencyFlags, uint32_t,
                          const VkMemoryBarrier*, uint32_t, const VkBufferMemoryBarrier*, uint32_t,
                          const VkImageMemoryBarrier*) {}

TEST_CASE("indirect capture unit: the recorder keeps each geometry's range facts as recorded, a null geometry's as "
          "unknown",
          "[unit][capture]") {
  RecordHarness h;
  DeviceDispatchTable next{};
  next.CmdCopyBuffer = NoCopy;
  next.CmdPipelineBarrier = NoBarrier;
  // No memory type: the pool gives no slab. No buffer holds the address either, so the info is logged as not
  // captured; its geometries' facts are kept all the same (what this test reads).
  const auto pool = std::make_shared<CapturePool>(VK_NULL_HANDLE, next, VkPhysicalDeviceMemoryProperties{});
  MemoryAliases aliases(VK_NULL_HANDLE, next, {}, VkDeviceSize{1} << 30);
  CaptureCounters counters;
  const CaptureContext ctx{h.state(), next, *pool, aliases, kCaptureUpdates, VkDeviceSize{1} << 20, counters};
  CommandBufferState recording(VK_NULL_HANDLE, VK_COMMAND_BUFFER_LEVEL_PRIMARY, false);

  VkAccelerationStructureGeometryKHR triangles{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  triangles.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  triangles.geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  triangles.geometry.triangles.vertexFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  triangles.geometry.triangles.indexType = VK_INDEX_TYPE_UINT16;
  triangles.geometry.triangles.maxVertex = 41;
  VkAccelerationStructureGeometryKHR aabbs{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  aabbs.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  aabbs.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
  const VkAccelerationStructureGeometryKHR* geometries[] = {&triangles, nullptr, &aabbs};
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.geometryCount = 3;
  info.ppGeometries = geometries;
  const VkDeviceAddress address = 0x10000;
  const uint32_t stride = 16;
  const uint32_t maxima[] = {1, 1, 1};
  const uint32_t* const max_counts[] = {maxima};
  std::vector<uint32_t> captured;
  REQUIRE(CaptureIndirectRanges(ctx, VK_NULL_HANDLE, recording, 1, &info, &address, &stride, max_counts, captured));
  // The app's structures may change or go once the call returns: the log holds copies.
  triangles.geometry.triangles.maxVertex = 0;
  triangles.geometry.triangles.indexType = VK_INDEX_TYPE_NONE_KHR;
  triangles.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;

  REQUIRE(recording.capture_log);
  const CaptureLog& log = *recording.capture_log;
  REQUIRE(log.infos.size() == 1);
  REQUIRE(log.geometries.size() == 3);
  const CapturedGeometry& tri = log.geometries[0];
  CHECK(tri.range_facts);
  CHECK(tri.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR);
  CHECK(tri.vertex_format == VK_FORMAT_R16G16B16A16_SFLOAT);
  CHECK(tri.index_type == VK_INDEX_TYPE_UINT16);
  CHECK(tri.max_vertex == 41);
  CHECK_FALSE(tri.data.present);  // only the range infos are captured
  CHECK_FALSE(log.geometries[1].range_facts);
  CHECK(log.geometries[2].range_facts);
  CHECK(log.geometries[2].type == VK_GEOMETRY_TYPE_AABBS_KHR);
}

}  // namespace
}  // namespace asval::test

namespace asval::test {
namespace {

// An indexed triangle geometry of an indirect info whose geometry the layer's dispatch reduced (issue 28): planned
// for `max` primitives, its results at byte 1024 of slab 0, with the index hash and the transform.
IndirectLog ReducedIndirect(uint32_t count, uint32_t max) {
  CapturedGeometry g = Triangles(VK_FORMAT_R32G32B32_SFLOAT, VK_INDEX_TYPE_UINT32, 3 * max - 1);
  g.reduced = true;
  g.range.primitiveCount = max;
  g.data = CapturedBytes{0, 1024, 4096, true};
  g.indices = CapturedBytes{0, 1024 + 60, 48, true};   // where the plan for `max` put them: not read
  g.transform = CapturedBytes{0, 1024 + 108, 48, true};
  IndirectLog made({Range{count, 36, 2, 16}}, {g}, {max}, 16);
  made.log->infos[0].indirect_geometry = true;
  return made;
}

TEST_CASE("indirect capture unit: an indirect geometry is read as the device laid it out for the range info's count",
          "[unit][capture]") {
  const IndirectLog made = ReducedIndirect(40, 100);
  CapturedGeometry g;
  REQUIRE(ExecutedGeometry(*made.log, made.log->infos[0], 0, &g));
  CHECK(g.range.primitiveCount == 40);
  // The offsets were applied on the device: none is left to apply.
  CHECK(g.range.primitiveOffset == 0);
  CHECK(g.range.firstVertex == 0);
  CHECK(g.range.transformOffset == 0);
  // 40 triangles: three bit arrays of two words (24 bytes), then one index hash block (16), then the transform.
  CHECK(g.data.offset == 1024);
  CHECK(g.indices.offset == 1024 + 24);
  CHECK(g.indices.size == 16);
  CHECK(g.transform.offset == 1024 + 24 + 16);
  CHECK(g.transform.size == 48);
  CHECK(g.data.size == 24 + 16 + 48);
}

TEST_CASE("indirect capture unit: an indirect geometry whose count is above ppMaxPrimitiveCounts is unknown",
          "[unit][capture]") {
  const IndirectLog made = ReducedIndirect(101, 100);
  CapturedGeometry g;
  CHECK_FALSE(ExecutedGeometry(*made.log, made.log->infos[0], 0, &g));
  const IndirectLog at_most = ReducedIndirect(100, 100);
  CHECK(ExecutedGeometry(*at_most.log, at_most.log->infos[0], 0, &g));
}

TEST_CASE("indirect capture unit: an indirect array of instance pointers is read as gathered for the range's count",
          "[unit][capture]") {
  CapturedGeometry g = Facts(VK_GEOMETRY_TYPE_INSTANCES_KHR);
  g.array_of_pointers = true;
  g.range.primitiveCount = 8;
  g.pointers = CapturedBytes{0, 2048, 64, true};
  g.data = CapturedBytes{0, 2048 + 64, 512, true};
  IndirectLog made({Range{3, 0, 0, 0}}, {g}, {8}, 16);
  made.log->infos[0].indirect_geometry = true;
  CapturedGeometry out;
  REQUIRE(ExecutedGeometry(*made.log, made.log->infos[0], 0, &out));
  CHECK(out.range.primitiveCount == 3);
  CHECK(out.pointers.offset == 2048);
  CHECK(out.pointers.size == 24);      // 3 pointers
  CHECK(out.data.offset == 2048 + 24);  // then their records
  CHECK(out.data.size == 192);
}

TEST_CASE("indirect capture unit: without its geometry captured, an indirect info's geometry is as logged",
          "[unit][capture]") {
  const IndirectLog made({5}, {8}, 16);  // range infos only
  CapturedGeometry g;
  REQUIRE(ExecutedGeometry(*made.log, made.log->infos[0], 0, &g));
  CHECK(g.range.primitiveCount == 0);  // the facts only: its bytes stay absent
  CHECK_FALSE(g.data.present);
}

}  // namespace
}  // namespace asval::test
