#include "indirect_rules.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "build_report.h"
#include "history.h"

namespace asval {

namespace {

constexpr uint32_t kNamed = 4;  // geometries named in a message; the rest are counted

// Geometry j's primitiveCount as the device read it (range infos `indirect_stride` bytes apart).
uint32_t CapturedCount(const CaptureLog& log, const CapturedInfo& info, uint32_t j) {
  VkAccelerationStructureBuildRangeInfoKHR range;
  std::memcpy(&range, log.Bytes(info.ranges) + static_cast<std::size_t>(j) * info.indirect_stride, sizeof(range));
  return range.primitiveCount;
}

// The geometries an update's count comparison covers: those both it and its source's last build have (a
// different geometry count is its own rule, pInfos-03758, judged at submission).
uint32_t ComparedGeometries(const IndirectRangeCheck& c) {
  const CaptureLog* log = c.log.get();
  if (!c.source || !log || c.info >= log->infos.size()) return 0;
  return static_cast<uint32_t>(std::min<std::size_t>(log->infos[c.info].geometry_count, c.source->geometries.size()));
}

void CountSkips(const CheckContext& ctx, uint32_t skipped) {
  if (skipped != 0) ctx.state.checks_skipped_unknown_state.fetch_add(skipped, std::memory_order_relaxed);
}

std::string AndMore(uint32_t found) {
  return found > kNamed ? fmt::format(" (and {} more geometries)", found - kNamed) : std::string();
}

// ppMaxPrimitiveCounts-03653: no count above the maximum the command was recorded with.
void CheckMaximumCounts(const CheckContext& ctx, const IndirectRangeCheck& c, const CaptureLog& log,
                        const CapturedInfo& info) {
  uint32_t over = 0;
  std::string named;
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    const uint32_t count = CapturedCount(log, info, j);
    const uint32_t max = log.max_primitive_counts[info.first_geometry + j];
    if (count <= max) continue;
    if (over++ < kNamed) {
      named += fmt::format("{}geometry {}: primitiveCount {} > ppMaxPrimitiveCounts[{}][{}] = {}", over > 1 ? "; " : "",
                           j, count, c.build.element, j, max);
    }
  }
  if (over == 0) return;
  const char* command = OpCommandName(c.build.command);
  ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-ppMaxPrimitiveCounts-03653", command), Location(command),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst)},
                      fmt::format("{}: builds {}; on execution, the range infos at pIndirectDeviceAddresses[{}] held "
                                  "more primitives than the command's maximum: {}{}.",
                                  DescribeOrigin(c.build), Hex(c.dst), c.build.element, named, AndMore(over)));
}

// primitiveCount-03769: an update's counts are those its source was last built with. A source count the history
// does not know (the source was last built indirectly: its counts stayed on the device) is skipped and counted.
void CheckUpdateCounts(const CheckContext& ctx, const IndirectRangeCheck& c, const CaptureLog& log,
                       const CapturedInfo& info) {
  const BuildSnapshot& source = *c.source;
  const uint32_t common = ComparedGeometries(c);
  uint32_t differ = 0;
  uint32_t unknown = 0;
  std::string named;
  for (uint32_t j = 0; j < common; ++j) {
    const GeometryRecord& built = source.geometries[j];
    if (!built.primitive_count_known) {
      ++unknown;
      continue;
    }
    const uint32_t count = CapturedCount(log, info, j);
    if (count == built.primitive_count) continue;
    if (differ++ < kNamed) {
      named += fmt::format("{}geometry {}: primitiveCount {}, but the source's build had {}", differ > 1 ? "; " : "",
                           j, count, built.primitive_count);
    }
  }
  CountSkips(ctx, unknown);
  if (differ == 0) return;
  const char* command = OpCommandName(c.build.command);
  ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-primitiveCount-03769", command), Location(command),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.src),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst == c.src ? VK_NULL_HANDLE : c.dst)},
                      fmt::format("{}: updates {} from srcAccelerationStructure {}, which was last built by {}; on "
                                  "execution, the range infos at pIndirectDeviceAddresses[{}] held other primitive "
                                  "counts than that build: {}{}.",
                                  DescribeOrigin(c.build), Hex(c.dst), Hex(c.src), DescribeOrigin(source.origin),
                                  c.build.element, named, AndMore(differ)));
}

}  // namespace

void CheckIndirectRanges(const CheckContext& ctx, const IndirectRangeCheck& c) {
  const CaptureLog* log = c.log.get();
  const CapturedInfo* readable = log ? log->Readable(c.info) : nullptr;
  if (!readable || !readable->ranges.present) {
    // Neither rule can be judged: the maximum once, and each count an update would have compared.
    CountSkips(ctx, 1 + ComparedGeometries(c));
    return;
  }
  CheckMaximumCounts(ctx, c, *log, *readable);
  if (c.source) CheckUpdateCounts(ctx, c, *log, *readable);
}

}  // namespace asval
