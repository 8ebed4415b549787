#include "build_geometry_data.h"

#include <limits>

#include "build_report.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

constexpr VkDeviceSize kMaxStride = std::numeric_limits<uint32_t>::max();

Location TrianglesField(const BuildCommand& cmd, uint32_t i, uint32_t j, const char* field) {
  return GeometryLocation(cmd, i, j).Field("geometry").Field("triangles").Field(field);
}

Location AabbsField(const BuildCommand& cmd, uint32_t i, uint32_t j, const char* field) {
  return GeometryLocation(cmd, i, j).Field("geometry").Field("aabbs").Field(field);
}

bool ValidateVertexFormat(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                          const VkAccelerationStructureGeometryTrianglesDataKHR& tri) {
  const std::optional<VkFormatFeatureFlags> features = ctx.state.format_features.BufferFeatures(tri.vertexFormat);
  if (!features) {
    CountUnknownState(ctx);
    return false;
  }
  if (*features & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR) return false;
  return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexFormat-03797",
                     [&](std::string&) { return TrianglesField(cmd, i, j, "vertexFormat"); },
                     "({}) does not have VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR in the "
                     "device's VkFormatProperties::bufferFeatures (0x{:x}).",
                     string_VkFormat(tri.vertexFormat), *features);
}

bool ValidateTriangles(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                       const VkAccelerationStructureGeometryTrianglesDataKHR& tri) {
  bool skip = false;
  if (tri.vertexStride > kMaxStride) {
    skip |= ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03819",
                        [&](std::string&) { return TrianglesField(cmd, i, j, "vertexStride"); },
                        "({}) is greater than 2^32-1.", tri.vertexStride);
  }
  const VertexFormatAlignment alignment = AlignmentOfVertexFormat(tri.vertexFormat);
  if (alignment.bytes == 0) {
    CountUnknownState(ctx);  // vertexFormat-03797 speaks about such a format
  } else if ((tri.vertexStride & (alignment.bytes - 1)) != 0) {
    skip |= ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03735",
                        [&](std::string&) { return TrianglesField(cmd, i, j, "vertexStride"); },
                        "({}) is not a multiple of {} bytes, the {} of vertexFormat {}.", tri.vertexStride,
                        alignment.bytes, alignment.packed ? "size of the packed format" : "component size",
                        string_VkFormat(tri.vertexFormat));
  }
  skip |= ValidateVertexFormat(ctx, cmd, i, j, tri);
  if (tri.indexType != VK_INDEX_TYPE_UINT16 && tri.indexType != VK_INDEX_TYPE_UINT32 &&
      tri.indexType != VK_INDEX_TYPE_NONE_KHR) {
    skip |= ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryTrianglesDataKHR-indexType-03798",
                        [&](std::string&) { return TrianglesField(cmd, i, j, "indexType"); },
                        "({}) is not VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32 or VK_INDEX_TYPE_NONE_KHR.",
                        string_VkIndexType(tri.indexType));
  }
  return skip;
}

bool ValidateAabbs(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                   const VkAccelerationStructureGeometryAabbsDataKHR& aabbs) {
  bool skip = false;
  if ((aabbs.stride & 7) != 0) {
    skip |= ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545",
                        [&](std::string&) { return AabbsField(cmd, i, j, "stride"); }, "({}) is not a multiple of 8.",
                        aabbs.stride);
  }
  if (aabbs.stride > kMaxStride) {
    skip |= ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03820",
                        [&](std::string&) { return AabbsField(cmd, i, j, "stride"); }, "({}) is greater than 2^32-1.",
                        aabbs.stride);
  }
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
