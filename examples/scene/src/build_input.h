#pragma once
// Everything one element of pInfos needs, kept in one value so that the arrays the build info points to
// live as long as the input does. Also the small recording helpers shared by the scene's parts.
#include <vulkan/vulkan.h>

#include <vector>

#include "gpu.h"

namespace scene {

struct BuildInput {
  VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  VkBuildAccelerationStructureFlagsKHR flags = 0;
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;  // one per geometry

  // Points into this object: keep it alive and unmoved until the command is recorded.
  VkAccelerationStructureBuildGeometryInfoKHR Info(VkBuildAccelerationStructureModeKHR mode,
                                                   VkAccelerationStructureKHR src, VkAccelerationStructureKHR dst,
                                                   VkDeviceAddress scratch) const;
  VkAccelerationStructureBuildSizesInfoKHR QuerySizes(const Gpu& gpu) const;
};

// The same input with one more geometry that has no primitives (a copy of the last one, count 0).
BuildInput WithEmptyGeometry(BuildInput input);

// The largest of each size over several inputs: structures and scratch that fit every variant.
VkAccelerationStructureBuildSizesInfoKHR MaxSizes(const Gpu& gpu, const std::vector<BuildInput>& variants);

// A triangle geometry (opaque) reading vertices at `vertices` and, unless index_type is NONE, indices.
VkAccelerationStructureGeometryKHR TriangleGeometry(VkFormat format, VkDeviceAddress vertices, VkDeviceSize stride,
                                                    uint32_t max_vertex, VkIndexType index_type,
                                                    VkDeviceAddress indices, VkDeviceAddress transform);

// One vkCmdBuildAccelerationStructuresKHR over `infos`, each with the ranges of its input.
void RecordBuild(const Gpu& gpu, VkCommandBuffer cb, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                 const std::vector<const BuildInput*>& inputs);

// A global memory barrier.
void Barrier(VkCommandBuffer cb, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
             VkPipelineStageFlags dst_stage, VkAccessFlags dst_access);

// Build results (and build inputs written by shaders) made visible to the next build or to ray tracing.
constexpr VkPipelineStageFlags kBuildStage = VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR;
constexpr VkAccessFlags kBuildReads = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_SHADER_READ_BIT;
constexpr VkAccessFlags kBuildWrites = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;

}  // namespace scene
