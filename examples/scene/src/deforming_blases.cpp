#include "deforming_blases.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "shader_code.h"

namespace scene {

namespace {

constexpr VkDeviceSize kPositionStride = 4 * sizeof(float);  // the shader writes vec4; the build reads xyz

VkAccelerationStructureBuildRangeInfoKHR Range(const DeformingGeometry& g) {
  VkAccelerationStructureBuildRangeInfoKHR r{};
  r.primitiveCount = static_cast<uint32_t>(g.indices.size() / 3);
  return r;
}

}  // namespace

DeformingBlases::DeformingBlases(Gpu& gpu) : gpu_(gpu), meshes_(MakeDeformingMeshes()) {
  const VkDeviceSize rest_bytes = meshes_.rest.size() * sizeof(RestVertex);
  rest_ = gpu_.CreateBuffer(rest_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kHostVisible);
  std::memcpy(rest_.mapped, meshes_.rest.data(), rest_bytes);
  params_ = gpu_.CreateBuffer(sizeof(Params), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kHostVisible);
  params() = Params{0.0f, 0, static_cast<uint32_t>(meshes_.rest.size()), 0};

  const size_t cloth = meshes_.cloth.indices.size(), pole = meshes_.pole.indices.size();
  const size_t blob = meshes_.blob.indices.size();
  pole_indices_offset_ = AlignUp(cloth * sizeof(uint32_t), 64);
  blob_indices_offset_ = AlignUp(pole_indices_offset_ + pole * sizeof(uint32_t), 64);
  indices_ = gpu_.CreateBuffer(blob_indices_offset_ + blob * sizeof(uint32_t),
                               VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
                               Memory::kHostVisible);
  char* mapped = static_cast<char*>(indices_.mapped);
  std::memcpy(mapped, meshes_.cloth.indices.data(), cloth * sizeof(uint32_t));
  std::memcpy(mapped + pole_indices_offset_, meshes_.pole.indices.data(), pole * sizeof(uint32_t));
  std::memcpy(mapped + blob_indices_offset_, meshes_.blob.indices.data(), blob * sizeof(uint32_t));

  const VkDeviceSize positions_bytes = meshes_.rest.size() * kPositionStride;
  output_block_ = gpu_.CreateBlock(2 * AlignUp(positions_bytes, 65536), Memory::kDeviceLocal);
  for (Buffer& b : positions_) {
    b = gpu_.CreateBufferIn(output_block_, positions_bytes,
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  }
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, positions_[0].buffer, "animated vertices (even frames)");
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, positions_[1].buffer, "animated vertices (odd frames)");

  const BuildInput flag = FlagInput(0), blob_input = BlobInput(0);
  const VkAccelerationStructureBuildSizesInfoKHR flag_sizes =
      MaxSizes(gpu_, {flag, WithCompactionFlag(flag), WithEmptyGeometry(flag)});
  const VkAccelerationStructureBuildSizesInfoKHR blob_sizes =
      MaxSizes(gpu_, {blob_input, WithCompactionFlag(blob_input), WithEmptyGeometry(blob_input)});
  flag_ = gpu_.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                           flag_sizes.accelerationStructureSize, "flag (deforming)");
  blob_ = gpu_.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                           blob_sizes.accelerationStructureSize, "blob (deforming)");
  // One scratch buffer, a 128-byte-aligned slice per structure, big enough for a build or an update.
  const VkDeviceSize slice_alignment =
      std::max<VkDeviceSize>(128, gpu_.as_properties().minAccelerationStructureScratchOffsetAlignment);
  blob_scratch_offset_ =
      AlignUp(std::max(flag_sizes.buildScratchSize, flag_sizes.updateScratchSize), slice_alignment);
  scratch_ = gpu_.CreateBuffer(blob_scratch_offset_ + std::max(blob_sizes.buildScratchSize, blob_sizes.updateScratchSize),
                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kDeviceLocal);
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, scratch_.buffer, "deforming scratch");
  CreatePipeline();
}

DeformingBlases::~DeformingBlases() {
  gpu_.Destroy(pipe_);
  gpu_.Destroy(flag_);
  gpu_.Destroy(blob_);
  gpu_.Destroy(scratch_);
  for (Buffer& b : positions_) gpu_.Destroy(b);
  gpu_.Destroy(output_block_);
  gpu_.Destroy(indices_);
  gpu_.Destroy(params_);
  gpu_.Destroy(rest_);
}

void DeformingBlases::CreatePipeline() {
  VkDevice d = gpu_.device();
  std::array<VkDescriptorSetLayoutBinding, 3> bindings{};
  for (uint32_t i = 0; i < bindings.size(); ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = static_cast<uint32_t>(bindings.size());
  set_info.pBindings = bindings.data();
  Check(vkCreateDescriptorSetLayout(d, &set_info, nullptr, &pipe_.set_layout), "vkCreateDescriptorSetLayout");
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &pipe_.set_layout;
  Check(vkCreatePipelineLayout(d, &layout_info, nullptr, &pipe_.layout), "vkCreatePipelineLayout");

  VkShaderModule module = CreateShaderModule(d, Shader::kDeform);
  VkComputePipelineCreateInfo pipeline_info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  pipeline_info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipeline_info.stage.module = module;
  pipeline_info.stage.pName = "main";
  pipeline_info.layout = pipe_.layout;
  Check(vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &pipe_.pipeline), "vkCreateComputePipelines");
  vkDestroyShaderModule(d, module, nullptr);

  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 6};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 2;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &pool_size;
  Check(vkCreateDescriptorPool(d, &pool_info, nullptr, &pipe_.descriptor_pool), "vkCreateDescriptorPool");
  const std::array<VkDescriptorSetLayout, 2> layouts{pipe_.set_layout, pipe_.set_layout};
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = pipe_.descriptor_pool;
  alloc.descriptorSetCount = 2;
  alloc.pSetLayouts = layouts.data();
  Check(vkAllocateDescriptorSets(d, &alloc, sets_.data()), "vkAllocateDescriptorSets");
  for (uint32_t parity = 0; parity < 2; ++parity) {
    const VkDescriptorBufferInfo buffers[3] = {{rest_.buffer, 0, VK_WHOLE_SIZE},
                                               {positions_[parity].buffer, 0, VK_WHOLE_SIZE},
                                               {params_.buffer, 0, VK_WHOLE_SIZE}};
    std::array<VkWriteDescriptorSet, 3> writes{};
    for (uint32_t i = 0; i < 3; ++i) {
      writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      writes[i].dstSet = sets_[parity];
      writes[i].dstBinding = i;
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[i].pBufferInfo = &buffers[i];
    }
    vkUpdateDescriptorSets(d, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
  }
}

BuildInput DeformingBlases::FlagInput(uint32_t parity) const {
  const VkDeviceAddress positions = positions_[parity].address;
  BuildInput in;
  in.flags = kFlags;
  const DeformingGeometry& cloth = meshes_.cloth;
  const DeformingGeometry& pole = meshes_.pole;
  in.geometries = {
      TriangleGeometry(VK_FORMAT_R32G32B32_SFLOAT, positions + cloth.first_vertex * kPositionStride, kPositionStride,
                       cloth.vertex_count - 1, VK_INDEX_TYPE_UINT32, indices_.address, 0),
      TriangleGeometry(VK_FORMAT_R32G32B32_SFLOAT, positions + pole.first_vertex * kPositionStride, kPositionStride,
                       pole.vertex_count - 1, VK_INDEX_TYPE_UINT32, indices_.address + pole_indices_offset_, 0)};
  in.ranges = {Range(cloth), Range(pole)};
  return in;
}

BuildInput DeformingBlases::BlobInput(uint32_t parity) const {
  const DeformingGeometry& blob = meshes_.blob;
  BuildInput in;
  in.flags = kFlags;
  in.geometries = {TriangleGeometry(VK_FORMAT_R32G32B32_SFLOAT,
                                    positions_[parity].address + blob.first_vertex * kPositionStride, kPositionStride,
                                    blob.vertex_count - 1, VK_INDEX_TYPE_UINT32,
                                    indices_.address + blob_indices_offset_, 0)};
  in.ranges = {Range(blob)};
  return in;
}

BuildInput DeformingBlases::WithCompactionFlag(BuildInput input) {
  input.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
  return input;
}

void DeformingBlases::RecordAnimate(VkCommandBuffer cb, uint32_t parity) const {
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe_.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe_.layout, 0, 1, &sets_[parity], 0, nullptr);
  vkCmdDispatch(cb, static_cast<uint32_t>((meshes_.rest.size() + 63) / 64), 1, 1);
  Barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, kBuildStage, kBuildReads);
}

void DeformingBlases::RecordBuilds(VkCommandBuffer cb, uint32_t parity, VkBuildAccelerationStructureModeKHR mode) const {
  const bool update = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  const BuildInput flag = FlagInput(parity), blob = BlobInput(parity);
  RecordBuild(gpu_, cb,
              {flag.Info(mode, update ? flag_.handle : VK_NULL_HANDLE, flag_.handle, flag_scratch()),
               blob.Info(mode, update ? blob_.handle : VK_NULL_HANDLE, blob_.handle, blob_scratch())},
              {&flag, &blob});
  Barrier(cb, kBuildStage, kBuildWrites, kBuildStage, kBuildReads);
}

}  // namespace scene
