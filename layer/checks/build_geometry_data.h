#pragma once
// Per-geometry rules of VkAccelerationStructureGeometryTrianglesDataKHR and
// VkAccelerationStructureGeometryAabbsDataKHR (family "structure"), for geometry j of pInfos[i]: run by the
// structure family's walk (build_structure.cpp) and by the geometry pass (geometry_pass.h), through a judge
// (rule_judge.h).
#include <cstdint>
#include <limits>

#include "build_command.h"
#include "check_context.h"
#include "geometry_facts.h"
#include "vk_struct_chain.h"

namespace asval {

// The data rules, named for the reporting half: the clean path passes only this and indices.
enum class DataRule {
  kStrideMultiple,
  kStrideMax,
  kVertexFormat,
  kIndexType,
  kAabbStride,
  kAabbStrideMax,
  // VkAccelerationStructureTrianglesOpacityMicromapEXT in the triangles' pNext chain (VK_EXT_opacity_micromap).
  kMicromapUsageCounts,     // pUsageCounts-07335
  kMicromapIndexType,       // indexType-10719
  kMicromapStrideMultiple,  // indexType-10722
  kMicromapStrideMax,       // indexType-10723
};

[[gnu::cold, gnu::noinline]] bool ReportGeometryData(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                     uint32_t j, DataRule rule, VkFormatFeatureFlags features = 0);

// The opacity micromap a triangles geometry's pNext chain names (VkAccelerationStructureTrianglesOpacityMicromapEXT):
// one array of usage counts, an index type and stride the build can read. Out of line: the clean path of a geometry
// without a pNext chain only compares the pointer.
template <typename Judge>
[[gnu::noinline]] bool OpacityMicromapRules(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                            const VkAccelerationStructureGeometryTrianglesDataKHR& tri,
                                            const Judge& judge) {
  const auto* micromap = FindInChain<VkAccelerationStructureTrianglesOpacityMicromapEXT>(
      tri.pNext, VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT);
  if (!micromap) return false;
  const auto broken = [&](DataRule rule) {
    return judge.Broken([&] { return ReportGeometryData(ctx, cmd, i, j, rule); });
  };
  bool skip = false;
  if (micromap->pUsageCounts && micromap->ppUsageCounts) skip |= broken(DataRule::kMicromapUsageCounts);
  VkDeviceSize index_bytes = 0;
  switch (micromap->indexType) {
    case VK_INDEX_TYPE_NONE_KHR:
      return skip;  // the triangle's own index: no stride is read
    case VK_INDEX_TYPE_UINT16:
      index_bytes = 2;
      break;
    case VK_INDEX_TYPE_UINT32:
      index_bytes = 4;
      break;
    default:
      return skip | broken(DataRule::kMicromapIndexType);
  }
  if (micromap->indexStride % index_bytes != 0) skip |= broken(DataRule::kMicromapStrideMultiple);
  if (micromap->indexStride > std::numeric_limits<uint32_t>::max()) skip |= broken(DataRule::kMicromapStrideMax);
  return skip;
}

template <typename Judge>
[[gnu::always_inline]] inline bool GeometryDataRules(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                     uint32_t j, const GeometryFacts& f, const Judge& judge) {
  constexpr VkDeviceSize kMaxStride = std::numeric_limits<uint32_t>::max();
  const auto broken = [&](DataRule rule, VkFormatFeatureFlags features = 0) {
    return judge.Broken([&] { return ReportGeometryData(ctx, cmd, i, j, rule, features); });
  };
  bool skip = false;
  switch (f.geometry.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
      const VkAccelerationStructureGeometryTrianglesDataKHR& tri = f.geometry.geometry.triangles;
      if (tri.vertexStride > kMaxStride) skip |= broken(DataRule::kStrideMax);
      const uint32_t alignment = f.format.componentBytes;
      if (alignment == 0) {
        skip |= judge.Unknown();  // vertexFormat-03797 speaks about such a format
      } else if ((tri.vertexStride & (alignment - 1)) != 0) {
        skip |= broken(DataRule::kStrideMultiple);
      }
      const std::optional<VkFormatFeatureFlags>& features = f.features;
      if (!features) {
        skip |= judge.Unknown();
      } else if (!(*features & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR)) {
        skip |= broken(DataRule::kVertexFormat, *features);
      }
      if (f.index_size != 0 && f.index_size != 2 && f.index_size != 4) skip |= broken(DataRule::kIndexType);
      if (tri.pNext) skip |= OpacityMicromapRules(ctx, cmd, i, j, tri, judge);
      return skip;
    }
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      const VkAccelerationStructureGeometryAabbsDataKHR& aabbs = f.geometry.geometry.aabbs;
      if ((aabbs.stride & 7) != 0) skip |= broken(DataRule::kAabbStride);
      if (aabbs.stride > kMaxStride) skip |= broken(DataRule::kAabbStrideMax);
      return skip;
    }
    default:
      return false;  // instances have no data rule here; types of newer extensions are not this layer's
  }
}

}  // namespace asval
