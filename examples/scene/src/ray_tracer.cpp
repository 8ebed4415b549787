#include "ray_tracer.h"

#include <cmath>
#include <cstring>
#include <vector>

#include "shader_code.h"

namespace scene {

namespace {

enum Group : uint32_t { kRaygenGroup, kSkyGroup, kShadowGroup, kTriangleGroup, kSphereGroup, kGroupCount };

struct CameraData {  // shaders/raygen.rgen's Camera
  float eye[4];
  float forward[4];
  float right[4];
  float up[4];
};

}  // namespace

RayTracer::RayTracer(Gpu& gpu, uint32_t width, uint32_t height) : gpu_(gpu), width_(width), height_(height) {
  image_ = gpu_.CreateBuffer(VkDeviceSize{width} * height * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kHostVisible);
  std::memset(image_.mapped, 0, image_.size);
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, image_.buffer, "image");
  camera_ = gpu_.CreateBuffer(sizeof(CameraData), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, Memory::kHostVisible);
  CreatePipeline();
  CreateShaderBindingTable();
}

RayTracer::~RayTracer() {
  gpu_.Destroy(pipe_);
  gpu_.Destroy(sbt_);
  gpu_.Destroy(camera_);
  gpu_.Destroy(image_);
}

void RayTracer::CreatePipeline() {
  VkDevice d = gpu_.device();
  const VkShaderStageFlags hit_stages = VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
  const std::array<VkDescriptorSetLayoutBinding, 3> bindings{{
      {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR | hit_stages, nullptr},
      {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
      {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
  }};
  VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = static_cast<uint32_t>(bindings.size());
  set_info.pBindings = bindings.data();
  Check(vkCreateDescriptorSetLayout(d, &set_info, nullptr, &pipe_.set_layout), "vkCreateDescriptorSetLayout");
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &pipe_.set_layout;
  Check(vkCreatePipelineLayout(d, &layout_info, nullptr, &pipe_.layout), "vkCreatePipelineLayout");

  struct StageSource {
    Shader shader;
    VkShaderStageFlagBits stage;
  };
  const StageSource sources[] = {{Shader::kRaygen, VK_SHADER_STAGE_RAYGEN_BIT_KHR},
                                 {Shader::kSkyMiss, VK_SHADER_STAGE_MISS_BIT_KHR},
                                 {Shader::kShadowMiss, VK_SHADER_STAGE_MISS_BIT_KHR},
                                 {Shader::kTriangleHit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR},
                                 {Shader::kSphereIntersection, VK_SHADER_STAGE_INTERSECTION_BIT_KHR},
                                 {Shader::kSphereHit, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR}};
  std::vector<VkPipelineShaderStageCreateInfo> stages;
  for (const StageSource& s : sources) {
    VkPipelineShaderStageCreateInfo stage{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stage.stage = s.stage;
    stage.module = CreateShaderModule(d, s.shader);
    stage.pName = "main";
    stages.push_back(stage);
  }
  auto group = [](VkRayTracingShaderGroupTypeKHR type, uint32_t general, uint32_t closest, uint32_t intersection) {
    VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    g.type = type;
    g.generalShader = general;
    g.closestHitShader = closest;
    g.anyHitShader = VK_SHADER_UNUSED_KHR;
    g.intersectionShader = intersection;
    return g;
  };
  const uint32_t none = VK_SHADER_UNUSED_KHR;
  const std::array<VkRayTracingShaderGroupCreateInfoKHR, kGroupCount> groups{
      group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR, 0, none, none),
      group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR, 1, none, none),
      group(VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR, 2, none, none),
      group(VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR, none, 3, none),
      group(VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR, none, 5, 4)};
  VkRayTracingPipelineCreateInfoKHR info{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  info.stageCount = static_cast<uint32_t>(stages.size());
  info.pStages = stages.data();
  info.groupCount = static_cast<uint32_t>(groups.size());
  info.pGroups = groups.data();
  info.maxPipelineRayRecursionDepth = 2;  // primary ray, then the shadow ray from the hit shaders
  info.layout = pipe_.layout;
  Check(gpu_.vk().CreateRayTracingPipelinesKHR(d, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &info, nullptr, &pipe_.pipeline),
        "vkCreateRayTracingPipelinesKHR");
  for (const VkPipelineShaderStageCreateInfo& s : stages) vkDestroyShaderModule(d, s.module, nullptr);

  const std::array<VkDescriptorPoolSize, 2> pool_sizes{{{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                                        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}}};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = static_cast<uint32_t>(pool_sizes.size());
  pool_info.pPoolSizes = pool_sizes.data();
  Check(vkCreateDescriptorPool(d, &pool_info, nullptr, &pipe_.descriptor_pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = pipe_.descriptor_pool;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &pipe_.set_layout;
  Check(vkAllocateDescriptorSets(d, &alloc, &set_), "vkAllocateDescriptorSets");
}

void RayTracer::CreateShaderBindingTable() {
  const VkPhysicalDeviceRayTracingPipelinePropertiesKHR& p = gpu_.rt_properties();
  const uint32_t handle_size = p.shaderGroupHandleSize;
  const VkDeviceSize record = AlignUp(handle_size, p.shaderGroupHandleAlignment);
  const VkDeviceSize base = p.shaderGroupBaseAlignment;
  std::vector<uint8_t> handles(size_t{kGroupCount} * handle_size);
  Check(gpu_.vk().GetRayTracingShaderGroupHandlesKHR(gpu_.device(), pipe_.pipeline, 0, kGroupCount, handles.size(),
                                                     handles.data()),
        "vkGetRayTracingShaderGroupHandlesKHR");
  // Three regions, each starting at a multiple of shaderGroupBaseAlignment: raygen | sky, shadow | triangles, spheres.
  const VkDeviceSize raygen_offset = 0;
  const VkDeviceSize miss_offset = AlignUp(record, base);
  const VkDeviceSize hit_offset = miss_offset + AlignUp(2 * record, base);
  const VkDeviceSize total = hit_offset + 2 * record;
  sbt_ = gpu_.CreateBuffer(total + base, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR, Memory::kHostVisible);
  gpu_.Name(VK_OBJECT_TYPE_BUFFER, sbt_.buffer, "shader binding table");
  // The buffer's address may be less aligned than shaderGroupBaseAlignment: start the table where it is.
  const VkDeviceSize start = AlignUp(sbt_.address, base) - sbt_.address;
  uint8_t* table = static_cast<uint8_t*>(sbt_.mapped) + start;
  auto put = [&](VkDeviceSize offset, uint32_t group) {
    std::memcpy(table + offset, handles.data() + size_t{group} * handle_size, handle_size);
  };
  put(raygen_offset, kRaygenGroup);
  put(miss_offset, kSkyGroup);
  put(miss_offset + record, kShadowGroup);
  put(hit_offset, kTriangleGroup);
  put(hit_offset + record, kSphereGroup);
  const VkDeviceAddress address = sbt_.address + start;
  raygen_region_ = {address + raygen_offset, AlignUp(record, base), AlignUp(record, base)};
  miss_region_ = {address + miss_offset, record, 2 * record};
  hit_region_ = {address + hit_offset, record, 2 * record};
}

void RayTracer::SetScene(VkAccelerationStructureKHR tlas) {
  VkWriteDescriptorSetAccelerationStructureKHR as_write{
      VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  as_write.accelerationStructureCount = 1;
  as_write.pAccelerationStructures = &tlas;
  const VkDescriptorBufferInfo image{image_.buffer, 0, VK_WHOLE_SIZE};
  const VkDescriptorBufferInfo camera{camera_.buffer, 0, VK_WHOLE_SIZE};
  std::array<VkWriteDescriptorSet, 3> writes{};
  for (uint32_t i = 0; i < 3; ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = set_;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  }
  writes[0].pNext = &as_write;
  writes[1].pBufferInfo = &image;
  writes[2].pBufferInfo = &camera;
  vkUpdateDescriptorSets(gpu_.device(), static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

void RayTracer::SetCamera(const float eye[3], const float target[3], float vertical_fov_degrees) {
  float f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
  const float fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (float& c : f) c /= fl;
  // right = forward x up(0,1,0); up = right x forward
  float r[3] = {-f[2], 0.0f, f[0]};
  const float rl = std::sqrt(r[0] * r[0] + r[2] * r[2]);
  for (float& c : r) c /= rl;
  const float u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
  const float half_height = std::tan(vertical_fov_degrees * 3.1415927f / 360.0f);
  const float half_width = half_height * static_cast<float>(width_) / static_cast<float>(height_);
  CameraData c{{eye[0], eye[1], eye[2], 0},
               {f[0], f[1], f[2], 0},
               {r[0] * half_width, r[1] * half_width, r[2] * half_width, 0},
               {u[0] * half_height, u[1] * half_height, u[2] * half_height, 0}};
  std::memcpy(camera_.mapped, &c, sizeof(c));
}

void RayTracer::RecordTrace(VkCommandBuffer cb) const {
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipe_.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipe_.layout, 0, 1, &set_, 0, nullptr);
  gpu_.vk().CmdTraceRaysKHR(cb, &raygen_region_, &miss_region_, &hit_region_, &callable_region_, width_, height_, 1);
  const VkPipelineStageFlags host = VK_PIPELINE_STAGE_HOST_BIT;
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, host, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace scene
