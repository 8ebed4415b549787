#include "build_ranges.h"

#include <cstring>

#include "build_report.h"
#include "host_reads.h"
#include "rule_judge.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

// The largest of `count` indices of `size` bytes at `data` (which need not be aligned).
uint32_t LargestIndex(const uint8_t* data, uint64_t count, int size) {
  uint32_t largest = 0;
  if (size == 2) {
    for (uint64_t k = 0; k < count; ++k) {
      uint16_t index;
      std::memcpy(&index, data + k * 2, sizeof(index));
      if (index > largest) largest = index;
    }
  } else {
    for (uint64_t k = 0; k < count; ++k) {
      uint32_t index;
      std::memcpy(&index, data + k * 4, sizeof(index));
      if (index > largest) largest = index;
    }
  }
  return largest;
}

[[gnu::cold, gnu::noinline]] bool ReportLargestIndex(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                     uint32_t j, uint32_t largest) {
  const VkAccelerationStructureGeometryTrianglesDataKHR& tri = GeometryAt(cmd.infos[i], j)->geometry.triangles;
  const VkAccelerationStructureBuildRangeInfoKHR& range = cmd.ranges[i][j];
  return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureBuildRangeInfoKHR-maxVertex-10774",
                     [&](std::string&) {
                       return GeometryLocation(cmd, i, j).Field("geometry").Field("triangles").Field("maxVertex");
                     },
                     "({}) is less than ppBuildRangeInfos[{}][{}].firstVertex ({}) plus the largest index the "
                     "build reads ({}, among the {} {} indices at indexData.hostAddress + primitiveOffset {}).",
                     tri.maxVertex, i, j, range.firstVertex, largest, uint64_t{range.primitiveCount} * 3,
                     string_VkIndexType(tri.indexType), range.primitiveOffset);
}

}  // namespace

const char* RangeRuleVuid(RangeRule rule) {
  switch (rule) {
    case RangeRule::kIndexOffset:
      return "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03656";
    case RangeRule::kVertexOffset:
      return "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657";
    case RangeRule::kTransformOffset:
      return "VUID-VkAccelerationStructureBuildRangeInfoKHR-transformOffset-03658";
    case RangeRule::kAabbOffset:
      return "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03659";
    case RangeRule::kInstanceOffset:
      return "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03660";
    case RangeRule::kVertexCount:
      return "VUID-VkAccelerationStructureBuildRangeInfoKHR-vertexData-10418";
    case RangeRule::kLastVertex:
      return "VUID-VkAccelerationStructureBuildRangeInfoKHR-None-10775";
  }
  return "";
}

bool ReportRange(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, RangeRule rule) {
  const VkAccelerationStructureGeometryTrianglesDataKHR& tri = GeometryAt(cmd.infos[i], j)->geometry.triangles;
  const VkAccelerationStructureBuildRangeInfoKHR& range = cmd.ranges[i][j];
  // "ppBuildRangeInfos[i][j].<field>": a path element with two indices, built here.
  const auto range_field = [&cmd, i, j](const char* field) {
    return [&cmd, i, j, field](std::string& storage) {
      storage = fmt::format("ppBuildRangeInfos[{}][{}]", i, j);
      return cmd.Root().Field(storage.c_str()).Field(field);
    };
  };
  const auto max_vertex = [&](std::string&) {
    return GeometryLocation(cmd, i, j).Field("geometry").Field("triangles").Field("maxVertex");
  };
  const uint64_t vertices = uint64_t{range.primitiveCount} * 3;
  switch (rule) {
    case RangeRule::kIndexOffset:
      return ReportBuild(ctx, cmd, i, RangeRuleVuid(rule), range_field("primitiveOffset"),
                         "({}) is not a multiple of {}, the size of the geometry's indexType {}.",
                         range.primitiveOffset, IndexTypeSize(tri.indexType), string_VkIndexType(tri.indexType));
    case RangeRule::kVertexOffset: {
      const VertexFormatAlignment alignment = AlignmentOfVertexFormat(tri.vertexFormat);
      return ReportBuild(ctx, cmd, i, RangeRuleVuid(rule), range_field("primitiveOffset"),
                         "({}) is not a multiple of {} bytes, the {} of the non-indexed geometry's vertexFormat {}.",
                         range.primitiveOffset, alignment.bytes, alignment.What(), string_VkFormat(tri.vertexFormat));
    }
    case RangeRule::kTransformOffset:
      return ReportBuild(ctx, cmd, i, RangeRuleVuid(rule), range_field("transformOffset"),
                         "({}) is not a multiple of 16.", range.transformOffset);
    case RangeRule::kAabbOffset:
      return ReportBuild(ctx, cmd, i, RangeRuleVuid(rule), range_field("primitiveOffset"),
                         "({}) is not a multiple of 8 (the geometry is VK_GEOMETRY_TYPE_AABBS_KHR).",
                         range.primitiveOffset);
    case RangeRule::kInstanceOffset:
      return ReportBuild(ctx, cmd, i, RangeRuleVuid(rule), range_field("primitiveOffset"),
                         "({}) is not a multiple of 16 (the geometry is VK_GEOMETRY_TYPE_INSTANCES_KHR).",
                         range.primitiveOffset);
    case RangeRule::kVertexCount:
      return ReportBuild(ctx, cmd, i, RangeRuleVuid(rule), range_field("primitiveCount"),
                         "({}) triangles consume {} vertices from vertexData, more than the geometry's maxVertex "
                         "({}) + 1.",
                         range.primitiveCount, vertices, tri.maxVertex);
    case RangeRule::kLastVertex:
      return ReportBuild(ctx, cmd, i, RangeRuleVuid(rule), max_vertex,
                         "({}) is less than ppBuildRangeInfos[{}][{}].firstVertex ({}) + primitiveCount ({}) * 3 - 1 "
                         "= {}, the last vertex the non-indexed build reads.",
                         tri.maxVertex, i, j, range.firstVertex, range.primitiveCount,
                         uint64_t{range.firstVertex} + vertices - 1);
  }
  return false;
}

// maxVertex-10774 for a host build: the indices are in host memory now, so the largest can be read (where they may
// be read: host_reads.h; else the rule is skipped and counted).
bool ValidateIndexedVertexCount(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                const VkAccelerationStructureGeometryTrianglesDataKHR& tri,
                                const VkAccelerationStructureBuildRangeInfoKHR& range, int index_size) {
  if (range.primitiveCount == 0 || tri.indexData.hostAddress == nullptr) return false;
  const uint64_t count = uint64_t{range.primitiveCount} * 3;
  if (!HostBytesReadable(ctx.state, tri.indexData.hostAddress, range.primitiveOffset + count * index_size)) {
    CountUnknownState(ctx);
    return false;
  }
  const auto* data = static_cast<const uint8_t*>(tri.indexData.hostAddress) + range.primitiveOffset;
  const uint32_t largest = LargestIndex(data, count, index_size);
  if (uint64_t{range.firstVertex} + largest <= tri.maxVertex) return false;
  return ReportLargestIndex(ctx, cmd, i, j, largest);
}

namespace {

// ppBuildRangeInfos-03676: ppBuildRangeInfos[i] points to pInfos[i].geometryCount range infos. What the layer can see
// of that: a null element where the info has geometries (a pointer that is not null is taken as valid).
[[gnu::cold, gnu::noinline]] bool ReportNullRanges(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  return ReportBuild(ctx, cmd, i, "ppBuildRangeInfos-03676",
                     [&](std::string&) { return cmd.Root().Field("ppBuildRangeInfos", i); },
                     "is NULL, but pInfos[{}].geometryCount is {}: it must point to that many "
                     "VkAccelerationStructureBuildRangeInfoKHR structures.",
                     i, cmd.infos[i].geometryCount);
}

// The infos the command's geometry pass flagged for these rules, walked with the reporting judge (out of line:
// the clean path only tests the flags).
[[gnu::noinline]] bool WalkRanges(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  ReportingJudge judge{ctx};
  GeometryFactsReader facts(ctx.state);
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = cmd.ranges[i];
    // Infos in which the command's geometry pass found nothing for these rules are not walked again.
    if (!(resolved.info(i).walks & kWalkRanges)) continue;
    if (!ranges) {
      if (info.geometryCount != 0) skip |= ReportNullRanges(ctx, cmd, i);
      continue;
    }
    if (!GeometriesWalkable(ctx, info)) continue;
    for (uint32_t j = 0; j < info.geometryCount; ++j) {
      const VkAccelerationStructureGeometryKHR* geometry = GeometryAt(info, j);
      if (geometry) skip |= RangeRules(ctx, cmd, i, j, facts.Read(*geometry), ranges[j], judge);
    }
  }
  return skip;
}

}  // namespace

bool ValidateBuildRanges(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  if (!cmd.infos || !cmd.ranges || !(resolved.walks() & kWalkRanges)) return false;
  return WalkRanges(ctx, cmd, resolved);
}

}  // namespace asval
