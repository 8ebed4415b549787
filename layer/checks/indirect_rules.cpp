#include "indirect_rules.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "build_ranges.h"
#include "build_report.h"
#include "history.h"
#include "rule_judge.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

constexpr uint32_t kNamed = 4;  // geometries named in a message; the rest are counted

// Geometry j's range info as the device read it (range infos `indirect_stride` bytes apart, not necessarily
// aligned for the struct in the slab: copied out).
VkAccelerationStructureBuildRangeInfoKHR CapturedRange(const CaptureLog& log, const CapturedInfo& info, uint32_t j) {
  VkAccelerationStructureBuildRangeInfoKHR range;
  std::memcpy(&range, log.Bytes(info.ranges) + static_cast<std::size_t>(j) * info.indirect_stride, sizeof(range));
  return range;
}

uint32_t CapturedCount(const CaptureLog& log, const CapturedInfo& info, uint32_t j) {
  return CapturedRange(log, info, j).primitiveCount;
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

std::string AndMore(uint32_t found, const char* what = "geometries") {
  return found > kNamed ? fmt::format(" (and {} more {})", found - kNamed, what) : std::string();
}

// The range geometries pIndirectDeviceAddresses-03651 judges (one judgement per geometry), when it is on.
uint32_t RangeGeometries(const CheckContext& ctx, const IndirectRangeCheck& c) {
  const CaptureLog* log = c.log.get();
  if (!ctx.Enabled(kCheckStructure) || !log || c.info >= log->infos.size()) return 0;
  return log->infos[c.info].geometry_count;
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

// The range rules' facts (build_ranges.h) of a captured geometry whose range_facts were kept: the geometry as
// the command was recorded, read as the record-time check reads the app's.
struct CapturedRangeFacts {
  const CapturedGeometry& g;
  VkGeometryTypeKHR type() const { return g.type; }
  uint32_t component_bytes() const { return VertexFormatFacts(g.vertex_format).componentBytes; }
  int index_size() const { return IndexTypeSize(g.index_type); }
  uint32_t max_vertex() const { return g.max_vertex; }
};

// A broken range rule in words: the field, its value, what the rule asks of it, and the rule itself.
std::string DescribeRange(RangeRule rule, const CapturedGeometry& g,
                          const VkAccelerationStructureBuildRangeInfoKHR& r) {
  const uint64_t vertices = uint64_t{r.primitiveCount} * 3;
  std::string what;
  switch (rule) {
    case RangeRule::kIndexOffset:
      what = fmt::format("primitiveOffset {} is not a multiple of the index size {}", r.primitiveOffset,
                         IndexTypeSize(g.index_type));
      break;
    case RangeRule::kVertexOffset: {
      const VertexFormatAlignment alignment = AlignmentOfVertexFormat(g.vertex_format);
      what = fmt::format("primitiveOffset {} is not a multiple of {} bytes, the {} of the non-indexed vertexFormat {}",
                         r.primitiveOffset, alignment.bytes, alignment.What(), string_VkFormat(g.vertex_format));
      break;
    }
    case RangeRule::kTransformOffset:
      what = fmt::format("transformOffset {} is not a multiple of 16", r.transformOffset);
      break;
    case RangeRule::kAabbOffset:
      what = fmt::format("primitiveOffset {} is not a multiple of 8 (AABBs)", r.primitiveOffset);
      break;
    case RangeRule::kInstanceOffset:
      what = fmt::format("primitiveOffset {} is not a multiple of 16 (instances)", r.primitiveOffset);
      break;
    case RangeRule::kVertexCount:
      what = fmt::format("primitiveCount {} consumes {} vertices, more than maxVertex {} + 1", r.primitiveCount,
                         vertices, g.max_vertex);
      break;
    case RangeRule::kLastVertex:
      what = fmt::format("firstVertex {} + primitiveCount {} * 3 - 1 = {} is past maxVertex {}", r.firstVertex,
                         r.primitiveCount, uint64_t{r.firstVertex} + vertices - 1, g.max_vertex);
      break;
  }
  // The rule without its "VUID-" prefix: the finding's own VUID is 03651.
  return fmt::format("{} ({})", what, RangeRuleVuid(rule) + std::strlen("VUID-"));
}

// pIndirectDeviceAddresses-03651: each range info the device read is a valid VkAccelerationStructureBuildRangeInfoKHR
// for its geometry, by the record-time range rules (build_ranges.h). maxVertex-10774 aside: it reads the indices,
// which stay on the device. A geometry whose facts were not kept, or whose vertex format the table lacks
// (03657), is skipped and counted.
void CheckCapturedRanges(const CheckContext& ctx, const IndirectRangeCheck& c, const CaptureLog& log,
                         const CapturedInfo& info) {
  const ReportingJudge judge{ctx};  // counts what it cannot judge; the findings are gathered below
  uint32_t broken = 0;
  uint32_t unknown = 0;
  std::string named;
  for (uint32_t j = 0; j < info.geometry_count; ++j) {
    const CapturedGeometry& g = log.geometries[info.first_geometry + j];
    if (!g.range_facts) {
      ++unknown;
      continue;
    }
    const VkAccelerationStructureBuildRangeInfoKHR range = CapturedRange(log, info, j);
    const auto note = [&](RangeRule rule) {
      if (broken++ < kNamed) {
        named += fmt::format("{}geometry {}: {}", broken > 1 ? "; " : "", j, DescribeRange(rule, g, range));
      }
      return false;  // the command ran long ago: there is no call to skip
    };
    JudgeRange(CapturedRangeFacts{g}, range, judge, note, [] { return false; });
  }
  CountSkips(ctx, unknown);
  if (broken == 0) return;
  const char* command = OpCommandName(c.build.command);
  ctx.reporter.Report(Severity::kError, fmt::format("VUID-{}-pIndirectDeviceAddresses-03651", command),
                      Location(command),
                      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, c.build.command_buffer),
                       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, c.dst)},
                      fmt::format("{}: builds {}; on execution, the range infos at pIndirectDeviceAddresses[{}] were "
                                  "not valid for their geometries: {}{}.",
                                  DescribeOrigin(c.build), Hex(c.dst), c.build.element, named,
                                  AndMore(broken, "findings")));
}

}  // namespace

void CheckIndirectRanges(const CheckContext& ctx, const IndirectRangeCheck& c) {
  const CaptureLog* log = c.log.get();
  const CapturedInfo* readable = log ? log->Readable(c.info) : nullptr;
  if (!readable || !readable->ranges.present) {
    // No rule can be judged: the maximum once, each geometry's range, and each count an update would have compared.
    CountSkips(ctx, 1 + RangeGeometries(ctx, c) + ComparedGeometries(c));
    return;
  }
  CheckMaximumCounts(ctx, c, *log, *readable);
  // The range rules are the structure family's, at record time as here.
  if (ctx.Enabled(kCheckStructure)) CheckCapturedRanges(ctx, c, *log, *readable);
  if (c.source) CheckUpdateCounts(ctx, c, *log, *readable);
}

}  // namespace asval
