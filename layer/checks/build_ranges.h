#pragma once
// Rules of VkAccelerationStructureBuildRangeInfoKHR (family "structure") for the direct and host builds,
// whose ranges the app passes on the host (an indirect build's ranges live in device memory):
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

[[gnu::cold, gnu::noinline]] bool ReportRange(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                              RangeRule rule);
// maxVertex-10774 for a host build (reads the app's indices).
bool ValidateIndexedVertexCount(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                const VkAccelerationStructureGeometryTrianglesDataKHR& tri,
                                const VkAccelerationStructureBuildRangeInfoKHR& range, int index_size);

// The rules above for geometry j of pInfos[i] and its range, through a judge (rule_judge.h).
template <typename Judge>
[[gnu::always_inline]] inline bool RangeRules(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, const GeometryFacts& f,
                const VkAccelerationStructureBuildRangeInfoKHR& range, const Judge& judge) {
  const auto broken = [&](RangeRule rule) { return judge.Broken([&] { return ReportRange(ctx, cmd, i, j, rule); }); };
  bool skip = false;
  switch (f.geometry.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      const VkAccelerationStructureGeometryTrianglesDataKHR& tri = f.geometry.geometry.triangles;
      const int index_size = f.index_size;
      if (index_size == 0) {
        const uint32_t alignment = f.format.componentBytes;
        if (alignment == 0) {
          skip |= judge.Unknown();
        } else if ((range.primitiveOffset & (alignment - 1)) != 0) {
          skip |= broken(RangeRule::kVertexOffset);
        }
        // Nothing is read when there are no triangles (firstVertex then names no vertex).
        if (range.primitiveCount != 0) {
          const uint64_t vertices = uint64_t{range.primitiveCount} * 3;
          if (vertices > uint64_t{tri.maxVertex} + 1) skip |= broken(RangeRule::kVertexCount);
          if (uint64_t{range.firstVertex} + vertices - 1 > tri.maxVertex) skip |= broken(RangeRule::kLastVertex);
        }
      } else if (index_size == 2 || index_size == 4) {
        if ((range.primitiveOffset & (index_size - 1)) != 0) {
          skip |= broken(RangeRule::kIndexOffset);
        } else if (cmd.is_host()) {
          // Indices read from a misaligned offset are not the app's indices: only an aligned range is judged.
          // Reading them is the reporting walk's (the geometry pass does not screen host builds).
          if constexpr (Judge::kReports) {
            skip |= ValidateIndexedVertexCount(ctx, cmd, i, j, tri, range, index_size);
          } else {
            skip |= judge.Unknown();
          }
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

}  // namespace asval
