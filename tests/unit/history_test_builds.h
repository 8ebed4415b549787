#pragma once
// Build infos of triangle geometries for the unit tests of the history: one geometry per count (its primitive
// count), kept alive with the info that points at them.
#include <vulkan/vulkan.h>

#include <vector>

namespace asval::test {

// One triangle geometry per count.
struct Build {
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = nullptr;

  Build(VkAccelerationStructureKHR dst, std::vector<uint32_t> counts, VkBuildAccelerationStructureFlagsKHR flags,
        VkAccelerationStructureKHR update_src = VK_NULL_HANDLE) {
    for (uint32_t count : counts) {
      VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
      g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
      g.geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      g.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
      g.geometry.triangles.maxVertex = 8;
      geometries.push_back(g);
      ranges.push_back(VkAccelerationStructureBuildRangeInfoKHR{count, 0, 0, 0});
    }
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.flags = flags;
    info.mode =
        update_src ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.srcAccelerationStructure = update_src;
    info.dstAccelerationStructure = dst;
    info.geometryCount = static_cast<uint32_t>(geometries.size());
    info.pGeometries = geometries.data();
    range_pointer = ranges.data();
  }
};


}  // namespace asval::test
