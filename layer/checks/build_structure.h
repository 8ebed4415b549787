#pragma once
// Structure rules of the build commands' inputs (family "structure"), for all three commands:
// VkAccelerationStructureBuildGeometryInfoKHR type-03654, pGeometries-03788, type-03789..03795, flags-03796,
// flags-07334; the geometry data rules of VkAccelerationStructureGeometryTrianglesDataKHR (vertexStride-03735,
// vertexStride-03819, vertexFormat-03797, indexType-03798) and VkAccelerationStructureGeometryAabbsDataKHR
// (stride-03545, stride-03820), and of the VkAccelerationStructureTrianglesOpacityMicromapEXT a triangles geometry
// chains (pUsageCounts-07335, indexType-10719, 10722, 10723). The range rules (VkAccelerationStructureBuildRangeInfoKHR) are in build_ranges.h.
// Only bits and values these headers name are judged: flag bits and geometry types of newer extensions are
// left alone.
#include <cstdint>

#include "build_command.h"
#include "build_geometry_data.h"
#include "check_context.h"
#include "geometry_facts.h"
#include "resolved_build.h"

namespace asval {

bool ValidateBuildStructure(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved);

// The reporting halves of the geometry rules below (cold, out of line).
[[gnu::cold, gnu::noinline]] bool ReportGeometryType(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                     uint32_t j, const char* suffix, const char* why);
[[gnu::cold, gnu::noinline]] bool ReportPrimitiveTotal(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                       bool aabbs, uint64_t total, uint64_t limit);

// The per-geometry rules of family "structure" for the geometries of pInfos[i], in order: Geometry for each
// geometry (the type rules type-03789, 03791, 03792, then the data rules of build_geometry_data.h), then Finish
// (the primitive totals of a bottom-level build, type-03794 / 03795). Through a judge (rule_judge.h).
template <typename Judge>
class StructureGeometryRules {
 public:
  StructureGeometryRules(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i)
      : ctx_(ctx),
        cmd_(cmd),
        i_(i),
        top_(cmd.infos[i].type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR),
        bottom_(cmd.infos[i].type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR),
        // Host-side primitive counts exist for direct and host builds; indirect counts live on the device.
        ranges_(cmd.ranges ? cmd.ranges[i] : nullptr),
        // Other structure types have no type rule.
        type_reported_(!top_ && !bottom_) {
    if (bottom_) {
      // The type every geometry of a bottom-level build must have: the first one's (the first non-null one: the
      // walks skip null geometries, or stop at one). A first instance geometry breaks type-03791 itself.
      const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
      for (uint32_t j = 0; j < info.geometryCount; ++j) {
        if (const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j)) {
          first_type_ = g->geometryType;
          break;
        }
      }
    }
    // A geometry of this type breaks no type rule; any other is judged by TypeRules.
    expected_ = top_ ? VK_GEOMETRY_TYPE_INSTANCES_KHR
                     : first_type_ == VK_GEOMETRY_TYPE_INSTANCES_KHR ? VK_GEOMETRY_TYPE_TRIANGLES_KHR : first_type_;
  }

  [[gnu::always_inline]] bool Geometry(uint32_t j, const GeometryFacts& f, const Judge& judge) {
    const VkGeometryTypeKHR type = f.geometry.geometryType;
    bool skip = false;
    if (type != expected_ && !type_reported_) skip |= TypeRules(j, type, judge);
    skip |= GeometryDataRules(ctx_, cmd_, i_, j, f, judge);
    if (bottom_ && ranges_) {
      if (type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) triangles_ += ranges_[j].primitiveCount;
      if (type == VK_GEOMETRY_TYPE_AABBS_KHR) aabbs_ += ranges_[j].primitiveCount;
    }
    return skip;
  }

  bool Finish(const Judge& judge) {
    if (!bottom_ || !ranges_) return false;
    const uint64_t limit = ctx_.state.properties.acceleration_structure.maxPrimitiveCount;
    if (limit == 0) return judge.Unknown();
    bool skip = false;
    if (aabbs_ > limit) skip |= judge.Broken([&] { return ReportPrimitiveTotal(ctx_, cmd_, i_, true, aabbs_, limit); });
    if (triangles_ > limit) {
      skip |= judge.Broken([&] { return ReportPrimitiveTotal(ctx_, cmd_, i_, false, triangles_, limit); });
    }
    return skip;
  }

 private:
  // type-03789, 03791, 03792 for a geometry whose type is not expected_ (the first finding of an info only).
  bool TypeRules(uint32_t j, VkGeometryTypeKHR type, const Judge& judge) {
    const char* suffix = nullptr;
    const char* why = nullptr;
    if (top_ && type != VK_GEOMETRY_TYPE_INSTANCES_KHR) {
      suffix = "type-03789";
      why = "is not VK_GEOMETRY_TYPE_INSTANCES_KHR, but the build is top-level.";
    } else if (bottom_ && type == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
      suffix = "type-03791";
      why = "is not allowed in a bottom-level build.";
    } else if (bottom_ && type != first_type_) {
      suffix = "type-03792";
      why = "differs from the geometryType of the info's first geometry: all geometries of a bottom-level build "
            "must have the same type.";
    }
    if (!suffix) return false;
    type_reported_ = true;
    return judge.Broken([&] { return ReportGeometryType(ctx_, cmd_, i_, j, suffix, why); });
  }

  const CheckContext& ctx_;
  const BuildCommand& cmd_;
  const uint32_t i_;
  const bool top_;
  const bool bottom_;
  const VkAccelerationStructureBuildRangeInfoKHR* const ranges_;
  bool type_reported_;
  VkGeometryTypeKHR first_type_ = VK_GEOMETRY_TYPE_MAX_ENUM_KHR;
  VkGeometryTypeKHR expected_;
  uint64_t triangles_ = 0;
  uint64_t aabbs_ = 0;
};

}  // namespace asval
