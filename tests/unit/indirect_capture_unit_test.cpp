// The rule an indirect build's captured range infos are judged by (ppMaxPrimitiveCounts-03653), at unit level on
// captured bytes: neither lavapipe nor the H200 builds indirectly, so no capture runs through a driver. The log is
// made by hand as layer/capture would fill it (the range infos copied from pIndirectDeviceAddresses[i], strided).
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <memory>
#include <vector>

#include "indirect_rules.h"
#include "record_checks_harness.h"

namespace asval::test {
namespace {

constexpr const char* kOverMaximum = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-ppMaxPrimitiveCounts-03653";

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

}  // namespace
}  // namespace asval::test
