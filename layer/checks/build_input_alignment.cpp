#include "build_input_alignment.h"

#include "build_report.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

// The input addresses these rules cover. The clean path passes only this and two numbers to the reporting
// half, so it materialises no message pieces (field names, lambdas) in its own frame.
enum class Input { kVertexData, kIndexData, kTransformData, kAabbData, kInstances, kInstancePointers };

[[gnu::cold, gnu::noinline]] bool ReportMisaligned(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                   uint32_t j, Input input, VkDeviceAddress address,
                                                   uint32_t alignment) {
  const VkAccelerationStructureGeometryKHR& g = *GeometryAt(cmd.infos[i], j);
  const char* vuid = "pInfos-03711";
  const char* kind = "triangles";
  const char* field = "vertexData";
  std::string why;
  switch (input) {
    case Input::kVertexData:
      why = fmt::format(", the {} of vertexFormat {}", AlignmentOfVertexFormat(g.geometry.triangles.vertexFormat).What(),
                        string_VkFormat(g.geometry.triangles.vertexFormat));
      break;
    case Input::kIndexData:
      vuid = "pInfos-03712";
      field = "indexData";
      why = fmt::format(", the size of indexType {}", string_VkIndexType(g.geometry.triangles.indexType));
      break;
    case Input::kTransformData:
      vuid = "pInfos-03810";
      field = "transformData";
      break;
    case Input::kAabbData:
      vuid = "pInfos-03714";
      kind = "aabbs";
      field = "data";
      break;
    case Input::kInstances:
      vuid = "pInfos-03715";
      kind = "instances";
      field = "data";
      why = " (arrayOfPointers is VK_FALSE: an array of VkAccelerationStructureInstanceKHR)";
      break;
    case Input::kInstancePointers:
      vuid = "pInfos-03716";
      kind = "instances";
      field = "data";
      why = " (arrayOfPointers is VK_TRUE: an array of pointers)";
      break;
  }
  return ReportBuild(
      ctx, cmd, i, vuid,
      [&](std::string&) {
        return GeometryLocation(cmd, i, j).Field("geometry").Field(kind).Field(field).Field("deviceAddress");
      },
      "(0x{:x}) is not aligned to {} bytes{}.", address, alignment, why);
}

bool ValidateTriangleAddresses(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                               const VkAccelerationStructureGeometryTrianglesDataKHR& tri) {
  bool skip = false;
  const VertexFormatAlignment alignment = AlignmentOfVertexFormat(tri.vertexFormat);
  if (alignment.bytes == 0) {
    CountUnknownState(ctx);
  } else if ((tri.vertexData.deviceAddress & (alignment.bytes - 1)) != 0) {
    skip |= ReportMisaligned(ctx, cmd, i, j, Input::kVertexData, tri.vertexData.deviceAddress, alignment.bytes);
  }
  const int index_size = IndexTypeSize(tri.indexType);
  if (index_size > 1 && (tri.indexData.deviceAddress & (index_size - 1)) != 0) {
    skip |= ReportMisaligned(ctx, cmd, i, j, Input::kIndexData, tri.indexData.deviceAddress,
                             static_cast<uint32_t>(index_size));
  }
  if ((tri.transformData.deviceAddress & 15) != 0) {
    skip |= ReportMisaligned(ctx, cmd, i, j, Input::kTransformData, tri.transformData.deviceAddress, 16);
  }
  return skip;
}

bool ValidateGeometryAddresses(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                               const VkAccelerationStructureGeometryKHR& geometry) {
  switch (geometry.geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
      return ValidateTriangleAddresses(ctx, cmd, i, j, geometry.geometry.triangles);
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      const VkDeviceAddress address = geometry.geometry.aabbs.data.deviceAddress;
      if ((address & 7) == 0) return false;
      return ReportMisaligned(ctx, cmd, i, j, Input::kAabbData, address, 8);
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      const VkAccelerationStructureGeometryInstancesDataKHR& instances = geometry.geometry.instances;
      const VkDeviceAddress address = instances.data.deviceAddress;
      if (instances.arrayOfPointers) {
        if ((address & 7) == 0) return false;
        return ReportMisaligned(ctx, cmd, i, j, Input::kInstancePointers, address, 8);
      }
      if ((address & 15) == 0) return false;
      return ReportMisaligned(ctx, cmd, i, j, Input::kInstances, address, 16);
    }
    default:
      return false;
  }
}

[[gnu::cold, gnu::noinline]] bool ReportIndirectArray(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                      bool stride) {
  if (stride) {
    return ReportBuild(ctx, cmd, i, "pIndirectStrides-03787",
                       [&](std::string&) { return cmd.Root().Field("pIndirectStrides", i); },
                       "({}) is not a multiple of 4.", cmd.indirect_strides[i]);
  }
  return ReportBuild(ctx, cmd, i, "pIndirectDeviceAddresses-03648",
                     [&](std::string&) { return cmd.Root().Field("pIndirectDeviceAddresses", i); },
                     "(0x{:x}) is not a multiple of 4.", cmd.indirect_addresses[i]);
}

bool ValidateIndirectArrays(const CheckContext& ctx, const BuildCommand& cmd) {
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    if (cmd.indirect_addresses && (cmd.indirect_addresses[i] & 3) != 0) skip |= ReportIndirectArray(ctx, cmd, i, false);
    if (cmd.indirect_strides && (cmd.indirect_strides[i] & 3) != 0) skip |= ReportIndirectArray(ctx, cmd, i, true);
  }
  return skip;
}

}  // namespace

bool ValidateInputAlignment(const CheckContext& ctx, const BuildCommand& cmd) {
  if (!cmd.infos || cmd.is_host()) return false;
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
    if (!GeometriesWalkable(ctx, info)) continue;
    for (uint32_t j = 0; j < info.geometryCount; ++j) {
      const VkAccelerationStructureGeometryKHR* geometry = GeometryAt(info, j);
      if (geometry) skip |= ValidateGeometryAddresses(ctx, cmd, i, j, *geometry);
    }
  }
  if (cmd.is_indirect()) skip |= ValidateIndirectArrays(ctx, cmd);
  return skip;
}

}  // namespace asval
