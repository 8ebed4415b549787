#include "build_input_alignment.h"

#include "build_report.h"
#include "vertex_format_alignment.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

// "pInfos[i].pGeometries[j].geometry.<kind>.<field>.deviceAddress".
auto AddressField(const BuildCommand& cmd, uint32_t i, uint32_t j, const char* kind, const char* field) {
  return [&cmd, i, j, kind, field](std::string&) {
    return GeometryLocation(cmd, i, j).Field("geometry").Field(kind).Field(field).Field("deviceAddress");
  };
}

bool ValidateTriangleAddresses(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                               const VkAccelerationStructureGeometryTrianglesDataKHR& tri) {
  bool skip = false;
  const VertexFormatAlignment alignment = AlignmentOfVertexFormat(tri.vertexFormat);
  if (alignment.bytes == 0) {
    CountUnknownState(ctx);
  } else if ((tri.vertexData.deviceAddress & (alignment.bytes - 1)) != 0) {
    skip |= ReportBuild(ctx, cmd, i, "pInfos-03711", AddressField(cmd, i, j, "triangles", "vertexData"),
                        "(0x{:x}) is not aligned to {} bytes, the {} of vertexFormat {}.",
                        tri.vertexData.deviceAddress, alignment.bytes,
                        alignment.packed ? "size of the packed format" : "component size",
                        string_VkFormat(tri.vertexFormat));
  }
  const int index_size = IndexTypeSize(tri.indexType);
  if (index_size > 1 && (tri.indexData.deviceAddress & (index_size - 1)) != 0) {
    skip |= ReportBuild(ctx, cmd, i, "pInfos-03712", AddressField(cmd, i, j, "triangles", "indexData"),
                        "(0x{:x}) is not aligned to {} bytes, the size of indexType {}.", tri.indexData.deviceAddress,
                        index_size, string_VkIndexType(tri.indexType));
  }
  if ((tri.transformData.deviceAddress & 15) != 0) {
    skip |= ReportBuild(ctx, cmd, i, "pInfos-03810", AddressField(cmd, i, j, "triangles", "transformData"),
                        "(0x{:x}) is not aligned to 16 bytes.", tri.transformData.deviceAddress);
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
      return ReportBuild(ctx, cmd, i, "pInfos-03714", AddressField(cmd, i, j, "aabbs", "data"),
                         "(0x{:x}) is not aligned to 8 bytes.", address);
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      const VkAccelerationStructureGeometryInstancesDataKHR& instances = geometry.geometry.instances;
      const VkDeviceAddress address = instances.data.deviceAddress;
      const uint32_t alignment = instances.arrayOfPointers ? 8 : 16;
      if ((address & (alignment - 1)) == 0) return false;
      return ReportBuild(ctx, cmd, i, instances.arrayOfPointers ? "pInfos-03716" : "pInfos-03715",
                         AddressField(cmd, i, j, "instances", "data"),
                         "(0x{:x}) is not aligned to {} bytes (arrayOfPointers is {}).", address, alignment,
                         instances.arrayOfPointers ? "VK_TRUE: an array of pointers" : "VK_FALSE: an array of "
                                                                                      "VkAccelerationStructureInstanceKHR");
    }
    default:
      return false;
  }
}

bool ValidateIndirectArrays(const CheckContext& ctx, const BuildCommand& cmd) {
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    if (cmd.indirect_addresses && (cmd.indirect_addresses[i] & 3) != 0) {
      skip |= ReportBuild(ctx, cmd, i, "pIndirectDeviceAddresses-03648",
                          [&](std::string&) { return cmd.Root().Field("pIndirectDeviceAddresses", i); },
                          "(0x{:x}) is not a multiple of 4.", cmd.indirect_addresses[i]);
    }
    if (cmd.indirect_strides && (cmd.indirect_strides[i] & 3) != 0) {
      skip |= ReportBuild(ctx, cmd, i, "pIndirectStrides-03787",
                          [&](std::string&) { return cmd.Root().Field("pIndirectStrides", i); },
                          "({}) is not a multiple of 4.", cmd.indirect_strides[i]);
    }
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
