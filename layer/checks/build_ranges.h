#pragma once
// Rules of VkAccelerationStructureBuildRangeInfoKHR (family "structure"), judged at record time for the direct and
// host builds, whose ranges the app passes on the host, and at completion for an indirect build's captured ranges
// (pIndirectDeviceAddresses-03651, indirect_rules.h; its ranges live in device memory):
//   primitiveOffset-03656  indexed triangles: a multiple of the index size
//   primitiveOffset-03657  non-indexed triangles: a multiple of the vertex format's component (packed) size
//   transformOffset-03658  triangles: a multiple of 16
//   primitiveOffset-03659  AABBs: a multiple of 8
//   primitiveOffset-03660  instances: a multiple of 16
//   vertexData-10418       non-indexed triangles: primitiveCount * 3 vertices fit in maxVertex + 1
//   None-10775             non-indexed triangles: maxVertex >= firstVertex + primitiveCount * 3 - 1
//   maxVertex-10774        indexed triangles, host builds only (the indices are host memory the layer can read
//                          now): maxVertex >= firstVertex + the largest index used
#include <cstdint>

#include "build_command.h"
#include "check_context.h"
#include "geometry_facts.h"
#include "resolved_build.h"

namespace asval {

bool ValidateBuildRanges(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);

// The range rules, named for the reporting half: the clean path passes only this and indices, so it
// materialises no message pieces in its own frame.
enum class RangeRule { kIndexOffset, kVertexOffset, kTransformOffset, kAabbOffset, kInstanceOffset, kVertexCount,
                       kLastVertex };

// Each rule's VUID, for every report of it: the record-time one (ReportRange) and the one an indirect build's
// captured ranges are judged by at completion (pIndirectDeviceAddresses-03651 names the rule it breaks).
const char* RangeRuleVuid(RangeRule rule);

// What the range rules read of one geometry, through accessors that JudgeRange calls only where a rule needs
// the value (the triangle ones for triangles only):
//   type()             the geometry type
//   component_bytes()  triangles: vertexFormat's alignment unit (03657); 0: a format the vertex table lacks
//   index_size()       triangles: IndexTypeSize(indexType)
//   max_vertex()       triangles: maxVertex
// The record-time check reads them from the app's geometry (below); an indirect build's check from what the
// capture kept when the command was recorded (indirect_rules.cpp). Accessors, not a struct filled up front: on the
// record-time hot path nothing is loaded before the rule that needs it, as when the rules read GeometryFacts.
struct GeometryRangeFacts {
  const GeometryFacts& f;
  VkGeometryTypeKHR type() const { return f.geometry.geometryType; }
  uint32_t component_bytes() const { return f.format.componentBytes; }
  int index_size() const { return f.index_size; }
  uint32_t max_vertex() const { return f.geometry.geometry.triangles.maxVertex; }
};

[[gnu::cold, gnu::noinline]] bool ReportRange(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                              RangeRule rule);
// maxVertex-10774 for a host build (reads the app's indices).
bool ValidateIndexedVertexCount(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                const VkAccelerationStructureGeometryTrianglesDataKHR& tri,
                                const VkAccelerationStructureBuildRangeInfoKHR& range, int index_size);

// The rules above (but maxVertex-10774) for one geometry's facts and range: the one place their arithmetic is
// written. Through a judge (rule_judge.h): report(rule) reports a broken rule and returns what judge.Broken
// returns; indexed() is run for indexed triangles whose primitiveOffset is aligned (indices read from a
// misaligned offset are not the app's indices), for what needs the indices themselves (maxVertex-10774, where
// they can be read).
template <typename Facts, typename Judge, typename Report, typename Indexed>
[[gnu::always_inline]] inline bool JudgeRange(const Facts& f, const VkAccelerationStructureBuildRangeInfoKHR& range,
                                              const Judge& judge, const Report& report, const Indexed& indexed) {
  const auto broken = [&](RangeRule rule) { return judge.Broken([&] { return report(rule); }); };
  bool skip = false;
  switch (f.type()) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      const int index_size = f.index_size();
      if (index_size == 0) {
        const uint32_t alignment = f.component_bytes();
        if (alignment == 0) {
          skip |= judge.Unknown();
        } else if ((range.primitiveOffset & (alignment - 1)) != 0) {
          skip |= broken(RangeRule::kVertexOffset);
        }
        // Nothing is read when there are no triangles (firstVertex then names no vertex).
        if (range.primitiveCount != 0) {
          const uint64_t vertices = uint64_t{range.primitiveCount} * 3;
          const uint32_t max_vertex = f.max_vertex();
          if (vertices > uint64_t{max_vertex} + 1) skip |= broken(RangeRule::kVertexCount);
          if (uint64_t{range.firstVertex} + vertices - 1 > max_vertex) skip |= broken(RangeRule::kLastVertex);
        }
      } else if (index_size == 2 || index_size == 4) {
        if ((range.primitiveOffset & (index_size - 1)) != 0) {
          skip |= broken(RangeRule::kIndexOffset);
        } else {
          skip |= indexed();
        }
      }
      // Other index types are indexType-03798's finding; their ranges are not judged.
      if ((range.transformOffset & 15) != 0) skip |= broken(RangeRule::kTransformOffset);
      return skip;
    }
    case VK_GEOMETRY_TYPE_AABBS_KHR:
      if ((range.primitiveOffset & 7) == 0) return false;
      return broken(RangeRule::kAabbOffset);
    case VK_GEOMETRY_TYPE_INSTANCES_KHR:
      if ((range.primitiveOffset & 15) == 0) return false;
      return broken(RangeRule::kInstanceOffset);
    default:
      return false;  // geometry types of newer extensions have rules of their own
  }
}

// The rules for geometry j of pInfos[i] and its range, as the app passed them (direct and host builds), reported
// against the command.
template <typename Judge>
[[gnu::always_inline]] inline bool RangeRules(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                              const GeometryFacts& f,
                                              const VkAccelerationStructureBuildRangeInfoKHR& range,
                                              const Judge& judge) {
  const auto report = [&](RangeRule rule) { return ReportRange(ctx, cmd, i, j, rule); };
  const auto indexed = [&] {
    if (!cmd.is_host()) return false;  // a device build's indices are device memory
    // Reading them is the reporting walk's (the geometry pass does not screen host builds).
    if constexpr (Judge::kReports) {
      return ValidateIndexedVertexCount(ctx, cmd, i, j, f.geometry.geometry.triangles, range, f.index_size);
    } else {
      return judge.Unknown();
    }
  };
  return JudgeRange(GeometryRangeFacts{f}, range, judge, report, indexed);
}

}  // namespace asval
