#include "geometry_pass.h"

#include "build_input_alignment.h"
#include "build_input_reads.h"
#include "build_ranges.h"
#include "build_report.h"
#include "build_sizes.h"
#include "build_structure.h"
#include "geometry_facts.h"
#include "rule_judge.h"

namespace asval {

void ScreenGeometries(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo* memo,
                      ResolvedInfo& r) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  r.walks = kWalkAll;
  if (cmd.is_host() || !GeometriesWalkable(ctx, info)) return;
  const bool structure = ctx.Enabled(kCheckStructure);
  const bool alignment = ctx.Enabled(kCheckAlignment);
  const bool addresses = memo && ctx.Enabled(kCheckAddresses);
  // The counts the rules read: ppBuildRangeInfos[i] (direct builds), ppMaxPrimitiveCounts[i] (indirect builds).
  // Without them the families' own walks decide what is judged.
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = nullptr;
  const uint32_t* max_counts = nullptr;
  if (cmd.is_indirect()) {
    if (!cmd.max_primitive_counts || !cmd.max_primitive_counts[i]) return;
    max_counts = cmd.max_primitive_counts[i];
  } else {
    if (!cmd.ranges || !cmd.ranges[i]) return;
    ranges = cmd.ranges[i];
  }
  const ScreeningJudge judge;
  StructureGeometryRules<ScreeningJudge> structure_rules(ctx, cmd, i);
  // Whether each family's rules found something (the screening rules return true then).
  bool structure_found = false, ranges_found = false, alignment_found = false, reads_found = false,
       counts_found = false;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
    if (!g) return;  // every family has its own way with a null geometry
    const GeometryFacts facts = FactsOf(*g);
    if (structure) {
      structure_found |= structure_rules.Geometry(j, facts, judge);
      if (ranges) ranges_found |= RangeRules(ctx, cmd, i, j, facts, ranges[j], judge);
    }
    if (alignment) alignment_found |= InputAlignmentRules(ctx, cmd, i, j, facts, judge);
    if (addresses) {
      // A geometry with no primitives (or a maximum of 0) reads nothing.
      const bool reads = ranges ? ranges[j].primitiveCount != 0 : max_counts[j] != 0;
      if (reads) reads_found |= InputReadRules(ctx, cmd, i, j, facts, ranges ? &ranges[j] : nullptr, *memo, judge);
      counts_found |= InstanceCountRule(ctx, cmd, i, j, facts, judge);
    }
  }
  if (structure) structure_found |= structure_rules.Finish(judge);
  r.walks = static_cast<uint8_t>((structure_found ? kWalkStructure : 0) | (ranges_found ? kWalkRanges : 0) |
                                 (alignment_found ? kWalkInputAlignment : 0) | (reads_found ? kWalkInputReads : 0) |
                                 (counts_found ? kWalkInstanceCounts : 0));
}

}  // namespace asval
