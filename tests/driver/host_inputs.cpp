#include "host_inputs.h"

#include <cstring>

namespace asval_test_driver {

uint32_t VertexFormatBytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32G32_SFLOAT:
      return 8;
    case VK_FORMAT_R32G32B32_SFLOAT:
      return 12;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return 16;
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R16G16_SNORM:
    case VK_FORMAT_R16G16_UNORM:
      return 4;
    case VK_FORMAT_R16G16B16_SFLOAT:
    case VK_FORMAT_R16G16B16_SNORM:
    case VK_FORMAT_R16G16B16_UNORM:
      return 6;
    case VK_FORMAT_R16G16B16A16_SFLOAT:
    case VK_FORMAT_R16G16B16A16_SNORM:
    case VK_FORMAT_R16G16B16A16_UNORM:
      return 8;
    case VK_FORMAT_R8G8_SNORM:
    case VK_FORMAT_R8G8_UNORM:
      return 2;
    case VK_FORMAT_R8G8B8_SNORM:
    case VK_FORMAT_R8G8B8_UNORM:
      return 3;
    case VK_FORMAT_R8G8B8A8_SNORM:
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
      return 4;
    case VK_FORMAT_R64G64_SFLOAT:
      return 16;
    case VK_FORMAT_R64G64B64_SFLOAT:
      return 24;
    case VK_FORMAT_R64G64B64A64_SFLOAT:
      return 32;
    default:
      return 0;
  }
}

uint32_t IndexBytes(VkIndexType type) {
  switch (type) {
    case VK_INDEX_TYPE_UINT8_EXT:
      return 1;
    case VK_INDEX_TYPE_UINT16:
      return 2;
    case VK_INDEX_TYPE_UINT32:
      return 4;
    default:
      return 0;
  }
}

HostSpan IndexSpan(const VkAccelerationStructureGeometryTrianglesDataKHR& triangles,
                   const VkAccelerationStructureBuildRangeInfoKHR& range) {
  const uint32_t index_bytes = IndexBytes(triangles.indexType);
  if (index_bytes == 0) return {};
  return {range.primitiveOffset, 3ull * range.primitiveCount * index_bytes};
}

HostSpan VertexSpan(const VkAccelerationStructureGeometryTrianglesDataKHR& triangles,
                    const VkAccelerationStructureBuildRangeInfoKHR& range, uint64_t largest_index) {
  if (range.primitiveCount == 0) return {};
  const uint64_t start = IndexBytes(triangles.indexType) == 0 ? range.primitiveOffset : 0;
  const uint64_t last = uint64_t{range.firstVertex} + largest_index;
  return {start, last * triangles.vertexStride + VertexFormatBytes(triangles.vertexFormat)};
}

uint64_t LargestIndex(const void* indices, VkIndexType type, uint64_t count) {
  const auto* bytes = static_cast<const unsigned char*>(indices);
  const uint32_t size = IndexBytes(type);
  uint64_t largest = 0;
  for (uint64_t i = 0; i < count; ++i) {
    uint32_t value = 0;  // little-endian: the low bytes of a uint32_t
    std::memcpy(&value, bytes + i * size, size);
    if (value > largest) largest = value;
  }
  return largest;
}

HostSpan TransformSpan(const VkAccelerationStructureGeometryTrianglesDataKHR& triangles,
                       const VkAccelerationStructureBuildRangeInfoKHR& range) {
  if (triangles.transformData.hostAddress == nullptr) return {};
  return {range.transformOffset, sizeof(VkTransformMatrixKHR)};
}

HostSpan AabbSpan(const VkAccelerationStructureGeometryAabbsDataKHR& aabbs,
                  const VkAccelerationStructureBuildRangeInfoKHR& range) {
  if (range.primitiveCount == 0) return {};
  return {range.primitiveOffset, (range.primitiveCount - 1ull) * aabbs.stride + sizeof(VkAabbPositionsKHR)};
}

HostSpan InstanceSpan(const VkAccelerationStructureGeometryInstancesDataKHR& instances,
                      const VkAccelerationStructureBuildRangeInfoKHR& range) {
  const uint64_t each = instances.arrayOfPointers ? sizeof(void*) : sizeof(VkAccelerationStructureInstanceKHR);
  return {range.primitiveOffset, each * range.primitiveCount};
}

void FoldFirstVertex(VkAccelerationStructureGeometryKHR& geometry, VkAccelerationStructureBuildRangeInfoKHR& range) {
  if (geometry.geometryType != VK_GEOMETRY_TYPE_TRIANGLES_KHR) return;
  auto& triangles = geometry.geometry.triangles;
  triangles.vertexData.deviceAddress += uint64_t{range.firstVertex} * triangles.vertexStride;
  range.firstVertex = 0;
}

}  // namespace asval_test_driver
