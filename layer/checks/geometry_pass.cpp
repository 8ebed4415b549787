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

namespace {

// Which families' rules the walk runs. kAllOn (the default settings: structure, alignment and addresses all on)
// and kDirect (ranges on the host, not maximum counts) are compile-time in the common case, so the loop carries
// no per-geometry tests of settings.
struct Families {
  bool structure;
  bool alignment;
  bool addresses;
};

template <bool kAllOn, bool kDirect>
uint8_t ScreenLoop(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo* memo,
                   Families on, const void* counts) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  const bool structure = kAllOn || on.structure;
  const bool alignment = kAllOn || on.alignment;
  const bool addresses = kAllOn || on.addresses;
  const auto* ranges = kDirect ? static_cast<const VkAccelerationStructureBuildRangeInfoKHR*>(counts) : nullptr;
  const auto* max_counts = kDirect ? nullptr : static_cast<const uint32_t*>(counts);
  const ScreeningJudge judge;
  StructureGeometryRules<ScreeningJudge> structure_rules(ctx, cmd, i);
  GeometryFactsReader reader(ctx.state);
  InputWindow window;
  // Whether each family's rules found something (the screening rules return true then).
  bool structure_found = false, ranges_found = false, alignment_found = false, reads_found = false,
       counts_found = false;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
    if (!g) return kWalkAll;  // every family has its own way with a null geometry
    const GeometryFacts facts = reader.Read(*g);
    if (structure) {
      structure_found |= structure_rules.Geometry(j, facts, judge);
      if (kDirect) ranges_found |= RangeRules(ctx, cmd, i, j, facts, ranges[j], judge);
    }
    if (alignment) alignment_found |= InputAlignmentRules(ctx, cmd, i, j, facts, judge);
    if (addresses) {
      // A geometry with no primitives (or a maximum of 0) reads nothing.
      const bool reads = kDirect ? ranges[j].primitiveCount != 0 : max_counts[j] != 0;
      if (reads) reads_found |= InputReadRules(ctx, cmd, i, j, facts, kDirect ? &ranges[j] : nullptr, *memo, window,
                                                 judge);
      counts_found |= InstanceCountRule(ctx, cmd, i, j, facts, judge);
    }
  }
  if (structure) structure_found |= structure_rules.Finish(judge);
  return static_cast<uint8_t>((structure_found ? kWalkStructure : 0) | (ranges_found ? kWalkRanges : 0) |
                              (alignment_found ? kWalkInputAlignment : 0) | (reads_found ? kWalkInputReads : 0) |
                              (counts_found ? kWalkInstanceCounts : 0));
}

}  // namespace

void ScreenGeometries(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo* memo,
                      ResolvedInfo& r) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  r.walks = kWalkAll;
  if (cmd.is_host() || !GeometriesWalkable(ctx, info)) return;
  // The default settings (every family on) in one mask test; the flags one by one only for the others.
  constexpr uint32_t kAll = kCheckStructure | kCheckAlignment | kCheckAddresses;
  const bool all_on = memo != nullptr && (ctx.enabled_checks & kAll) == kAll;
  const Families on{all_on || ctx.Enabled(kCheckStructure), all_on || ctx.Enabled(kCheckAlignment),
                    all_on || (memo != nullptr && ctx.Enabled(kCheckAddresses))};
  // The counts the rules read: ppBuildRangeInfos[i] (direct builds), ppMaxPrimitiveCounts[i] (indirect builds).
  // Without them the families' own walks decide what is judged.
  if (cmd.is_indirect()) {
    if (!cmd.max_primitive_counts || !cmd.max_primitive_counts[i]) return;
    const uint32_t* counts = cmd.max_primitive_counts[i];
    r.walks = all_on ? ScreenLoop<true, false>(ctx, cmd, i, memo, on, counts)
                     : ScreenLoop<false, false>(ctx, cmd, i, memo, on, counts);
  } else {
    if (!cmd.ranges || !cmd.ranges[i]) return;
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = cmd.ranges[i];
    r.walks = all_on ? ScreenLoop<true, true>(ctx, cmd, i, memo, on, ranges)
                     : ScreenLoop<false, true>(ctx, cmd, i, memo, on, ranges);
  }
}

}  // namespace asval
