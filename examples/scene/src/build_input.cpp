#include "build_input.h"

#include <algorithm>

namespace scene {

VkAccelerationStructureBuildGeometryInfoKHR BuildInput::Info(VkBuildAccelerationStructureModeKHR mode,
                                                             VkAccelerationStructureKHR src,
                                                             VkAccelerationStructureKHR dst,
                                                             VkDeviceAddress scratch) const {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = flags;
  info.mode = mode;
  info.srcAccelerationStructure = src;
  info.dstAccelerationStructure = dst;
  info.geometryCount = static_cast<uint32_t>(geometries.size());
  info.pGeometries = geometries.data();
  info.scratchData.deviceAddress = scratch;
  return info;
}

VkAccelerationStructureBuildSizesInfoKHR BuildInput::QuerySizes(const Gpu& gpu) const {
  std::vector<uint32_t> counts;
  for (const VkAccelerationStructureBuildRangeInfoKHR& r : ranges) counts.push_back(r.primitiveCount);
  const VkAccelerationStructureBuildGeometryInfoKHR info =
      Info(VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR, VK_NULL_HANDLE, VK_NULL_HANDLE, 0);
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  gpu.vk().GetAccelerationStructureBuildSizesKHR(gpu.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                                 counts.data(), &sizes);
  return sizes;
}

BuildInput WithEmptyGeometry(BuildInput input) {
  input.geometries.push_back(input.geometries.back());
  VkAccelerationStructureBuildRangeInfoKHR range = input.ranges.back();
  range.primitiveCount = 0;
  input.ranges.push_back(range);
  return input;
}

VkAccelerationStructureBuildSizesInfoKHR MaxSizes(const Gpu& gpu, const std::vector<BuildInput>& variants) {
  VkAccelerationStructureBuildSizesInfoKHR max{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  for (const BuildInput& v : variants) {
    const VkAccelerationStructureBuildSizesInfoKHR s = v.QuerySizes(gpu);
    max.accelerationStructureSize = std::max(max.accelerationStructureSize, s.accelerationStructureSize);
    max.buildScratchSize = std::max(max.buildScratchSize, s.buildScratchSize);
    max.updateScratchSize = std::max(max.updateScratchSize, s.updateScratchSize);
  }
  return max;
}

VkAccelerationStructureGeometryKHR TriangleGeometry(VkFormat format, VkDeviceAddress vertices, VkDeviceSize stride,
                                                    uint32_t max_vertex, VkIndexType index_type,
                                                    VkDeviceAddress indices, VkDeviceAddress transform) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.vertexFormat = format;
  t.vertexData.deviceAddress = vertices;
  t.vertexStride = stride;
  t.maxVertex = max_vertex;
  t.indexType = index_type;
  t.indexData.deviceAddress = indices;
  t.transformData.deviceAddress = transform;
  return g;
}

void RecordBuild(const Gpu& gpu, VkCommandBuffer cb, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                 const std::vector<const BuildInput*>& inputs) {
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges;
  for (const BuildInput* input : inputs) ranges.push_back(input->ranges.data());
  gpu.vk().CmdBuildAccelerationStructuresKHR(cb, static_cast<uint32_t>(infos.size()), infos.data(), ranges.data());
}

void Barrier(VkCommandBuffer cb, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
             VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  vkCmdPipelineBarrier(cb, src_stage, dst_stage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace scene
