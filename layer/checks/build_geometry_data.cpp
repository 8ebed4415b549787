#include "build_geometry_data.h"

#include <limits>

#include "build_report.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

bool ReportOpacityMicromap(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, DataRule rule,
                           const VkAccelerationStructureGeometryTrianglesDataKHR& tri) {
  const auto& m = *FindInChain<VkAccelerationStructureTrianglesOpacityMicromapEXT>(
      tri.pNext, VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT);
  const auto field = [&cmd, i, j](const char* name) {
    return [&cmd, i, j, name](std::string&) {
      return GeometryLocation(cmd, i, j)
          .Field("geometry")
          .Field("triangles")
          .Field("pNext<VkAccelerationStructureTrianglesOpacityMicromapEXT>")
          .Field(name);
    };
  };
  constexpr const char kVuid[] = "VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-";
  switch (rule) {
    case DataRule::kMicromapUsageCounts:
      return ReportBuild(ctx, cmd, i, std::string(kVuid) + "pUsageCounts-07335", field("pUsageCounts"),
                         "({}) and ppUsageCounts ({}) are both given: only one of them may be a valid pointer, the "
                         "other must be NULL.",
                         fmt::ptr(m.pUsageCounts), fmt::ptr(m.ppUsageCounts));
    case DataRule::kMicromapIndexType:
      return ReportBuild(ctx, cmd, i, std::string(kVuid) + "indexType-10719", field("indexType"),
                         "({}) is not VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32 or VK_INDEX_TYPE_NONE_KHR.",
                         string_VkIndexType(m.indexType));
    case DataRule::kMicromapStrideMultiple:
      return ReportBuild(ctx, cmd, i, std::string(kVuid) + "indexType-10722", field("indexStride"),
                         "({}) is not a multiple of {} bytes, the size of indexType {}.", m.indexStride,
                         m.indexType == VK_INDEX_TYPE_UINT16 ? 2 : 4, string_VkIndexType(m.indexType));
    case DataRule::kMicromapStrideMax:
      return ReportBuild(ctx, cmd, i, std::string(kVuid) + "indexType-10723", field("indexStride"),
                         "({}) is greater than 2^32-1.", m.indexStride);
    default:
      return false;
  }
}

}  // namespace

bool ReportGeometryData(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, DataRule rule,
                        VkFormatFeatureFlags features) {
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
    case DataRule::kMicromapUsageCounts:
    case DataRule::kMicromapIndexType:
    case DataRule::kMicromapStrideMultiple:
    case DataRule::kMicromapStrideMax:
      return ReportOpacityMicromap(ctx, cmd, i, j, rule, tri);
  }
  return false;
}

}  // namespace asval
