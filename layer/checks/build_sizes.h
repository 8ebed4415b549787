#pragma once
// The sizes the driver reports for one info of a build command, and the rules that compare with them
// (family "addresses"):
//   pInfos-10126 (older: 03675)   direct and host builds: dstAccelerationStructure was created at least as
//                                 large as accelerationStructureSize for this geometry and these counts
//   pInfos-03652                  indirect builds: the same, with ppMaxPrimitiveCounts[i] as the counts
//   pInfos-03801                  an instance geometry's count is at most maxInstanceCount
// The scratch rules that use the same sizes are in build_addresses.h.
#include <cstdint>

#include "build_command.h"
#include "build_size_lookup.h"
#include "check_context.h"
#include "geometry_facts.h"
#include "resolved_build.h"

namespace asval {

// pInfos-10126 / pInfos-03652 and pInfos-03801 for pInfos[i], all three commands.
bool ValidateInfoSizes(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r);

// Whether ValidateInfoSizes certainly has nothing to report or count for pInfos[i]: the geometry pass found no
// instance count to judge, and the destination is known and at least as large as the driver's size. Tested
// before any call, so that the clean path needs no stack frame.
inline bool InfoSizesClean(const ResolvedInfo& r) {
  return !(r.walks & kWalkInstanceCounts) && r.sizes && r.dst && r.dst->size >= r.sizes->acceleration_structure_size;
}

[[gnu::cold, gnu::noinline]] bool ReportInstanceCount(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                      uint32_t j, uint32_t count, uint64_t limit);

// pInfos-03801 for geometry j of pInfos[i], whose counts the command gives (ppBuildRangeInfos[i] or
// ppMaxPrimitiveCounts[i]), through a judge (rule_judge.h).
template <typename Judge>
[[gnu::always_inline]] inline bool InstanceCountRule(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                       const GeometryFacts& f, const Judge& judge) {
  if (f.geometry.geometryType != VK_GEOMETRY_TYPE_INSTANCES_KHR) return false;
  const uint64_t limit = ctx.state.properties.acceleration_structure.maxInstanceCount;
  if (limit == 0) return judge.Unknown();
  const uint32_t count = cmd.is_indirect() ? cmd.max_primitive_counts[i][j] : cmd.ranges[i][j].primitiveCount;
  if (count <= limit) return false;
  return judge.Broken([&] { return ReportInstanceCount(ctx, cmd, i, j, count, limit); });
}

}  // namespace asval
