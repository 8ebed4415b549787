#include "indirect_rules.h"

#include <fmt/format.h>

#include <cstring>
#include <string>

#include "build_report.h"

namespace asval {

namespace {

constexpr uint32_t kNamed = 4;  // geometries named in a message; the rest are counted

}  // namespace

void CheckIndirectRanges(const CheckContext& ctx, const IndirectRangeCheck& c) {
  const CaptureLog* log = c.log.get();
  const CapturedInfo* readable = log ? log->Readable(c.info) : nullptr;
  if (!readable || !readable->ranges.present) {
    ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  const CapturedInfo& info = *readable;
  const uint8_t* ranges = log->Bytes(info.ranges);
  uint32_t over = 0;
  std::string named;
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    VkAccelerationStructureBuildRangeInfoKHR range;
    std::memcpy(&range, ranges + static_cast<std::size_t>(j) * info.indirect_stride, sizeof(range));
    const uint32_t max = log->max_primitive_counts[info.first_geometry + j];
    if (range.primitiveCount <= max) continue;
    if (over++ < kNamed) {
      named += fmt::format("{}geometry {}: primitiveCount {} > ppMaxPrimitiveCounts[{}][{}] = {}", over > 1 ? "; " : "", j,
                           range.primitiveCount, c.build.element, j, max);
    }
  }
  if (over == 0) return;
  if (over > kNamed) named += fmt::format(" (and {} more geometries)", over - kNamed);
  const char* command = OpCommandName(c.build.command);
  ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-ppMaxPrimitiveCounts-03653", command), Location(command),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst)},
                      fmt::format("{}: builds {}; on execution, the range infos at pIndirectDeviceAddresses[{}] held "
                                  "more primitives than the command's maximum: {}.",
                                  DescribeOrigin(c.build), Hex(c.dst), c.build.element, named));
}

}  // namespace asval
