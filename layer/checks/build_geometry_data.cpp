#include "build_geometry_data.h"

#include <limits>

#include "build_report.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

constexpr VkDeviceSize kMaxStride = std::numeric_limits<uint32_t>::max();

// The data rules, named for the reporting half: the clean path passes only this and indices.
enum class DataRule { kStrideMultiple, kStrideMax, kVertexFormat, kIndexType, kAabbStride, kAabbStrideMax };

[[gnu::cold, gnu::noinline]] bool ReportData(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                             DataRule rule, VkFormatFeatureFlags features = 0) {
  const VkAccelerationStructureGeometryKHR& g = *GeometryAt(cmd.infos[i], j);
  const VkAccelerationStructureGeometryTrianglesDataKHR& tri = g.geometry.triangles;
  const auto triangles = [&](const char* field) {
    return [&cmd, i, j, field](std::string&) {
      return GeometryLocation(cmd, i, j).Field("geometry").Field("triangles").Field(field);
    };
  };
  const auto aabbs = [&](std::string&) {
    return GeometryLocation(cmd, i, j).Field("geometry").Field("aabbs").Field("stride");
  };
  switch (rule) {
    case DataRule::kStrideMultiple: {
      const VertexFormatAlignment alignment = AlignmentOfVertexFormat(tri.vertexFormat);
      return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03735",
                         triangles("vertexStride"), "({}) is not a multiple of {} bytes, the {} of vertexFormat {}.",
                         tri.vertexStride, alignment.bytes,
                         alignment.What(),
                         string_VkFormat(tri.vertexFormat));
    }
    case DataRule::kStrideMax:
      return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03819",
                         triangles("vertexStride"), "({}) is greater than 2^32-1.", tri.vertexStride);
    case DataRule::kVertexFormat:
      return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexFormat-03797",
                         triangles("vertexFormat"),
                         "({}) does not have VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR in the "
                         "device's VkFormatProperties::bufferFeatures (0x{:x}).",
                         string_VkFormat(tri.vertexFormat), features);
    case DataRule::kIndexType:
      return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-indexType-03798",
                         triangles("indexType"),
                         "({}) is not VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32 or VK_INDEX_TYPE_NONE_KHR.",
                         string_VkIndexType(tri.indexType));
    case DataRule::kAabbStride:
      return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545", aabbs,
                         "({}) is not a multiple of 8.", g.geometry.aabbs.stride);
    case DataRule::kAabbStrideMax:
      return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03820", aabbs,
                         "({}) is greater than 2^32-1.", g.geometry.aabbs.stride);
  }
  return false;
}

bool ValidateTriangles(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                       const VkAccelerationStructureGeometryTrianglesDataKHR& tri) {
  bool skip = false;
  if (tri.vertexStride > kMaxStride) skip |= ReportData(ctx, cmd, i, j, DataRule::kStrideMax);
  const VertexFormatAlignment alignment = AlignmentOfVertexFormat(tri.vertexFormat);
  if (alignment.bytes == 0) {
    CountUnknownState(ctx);  // vertexFormat-03797 speaks about such a format
  } else if ((tri.vertexStride & (alignment.bytes - 1)) != 0) {
    skip |= ReportData(ctx, cmd, i, j, DataRule::kStrideMultiple);
  }
  const std::optional<VkFormatFeatureFlags> features = ctx.state.format_features.BufferFeatures(tri.vertexFormat);
  if (!features) {
    CountUnknownState(ctx);
  } else if (!(*features & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR)) {
    skip |= ReportData(ctx, cmd, i, j, DataRule::kVertexFormat, *features);
  }
  if (tri.indexType != VK_INDEX_TYPE_UINT16 && tri.indexType != VK_INDEX_TYPE_UINT32 &&
      tri.indexType != VK_INDEX_TYPE_NONE_KHR) {
    skip |= ReportData(ctx, cmd, i, j, DataRule::kIndexType);
  }
  return skip;
}

bool ValidateAabbs(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                   const VkAccelerationStructureGeometryAabbsDataKHR& aabbs) {
  bool skip = false;
  if ((aabbs.stride & 7) != 0) skip |= ReportData(ctx, cmd, i, j, DataRule::kAabbStride);
  if (aabbs.stride > kMaxStride) skip |= ReportData(ctx, cmd, i, j, DataRule::kAabbStrideMax);
  return skip;
}

}  // namespace

bool ValidateGeometryData(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                          const VkAccelerationStructureGeometryKHR& geometry) {
  switch (geometry.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
      return ValidateTriangles(ctx, cmd, i, j, geometry.geometry.triangles);
    case VK_GEOMETRY_TYPE_AABBS_KHR:
      return ValidateAabbs(ctx, cmd, i, j, geometry.geometry.aabbs);
    default:
      return false;  // instances have no data rule here; types of newer extensions are not this layer's
  }
}

}  // namespace asval
