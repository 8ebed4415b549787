#include "ray_program.h"

#include <cstddef>
#include <cstring>
#include <vector>

#include "draw_ray.frag.h"
#include "draw_ray.vert.h"
#include "ray_query.comp.h"
#include "trace_miss.rmiss.h"
#include "trace_ray.rgen.h"

namespace asval_test {

namespace {

VkShaderModule MakeModule(VkDevice device, const uint32_t* code, std::size_t bytes) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = bytes;
  info.pCode = code;
  VkShaderModule module = VK_NULL_HANDLE;
  vkkit::Check(vkCreateShaderModule(device, &info, nullptr, &module), "vkCreateShaderModule");
  return module;
}

template <typename PFN>
PFN Proc(const vkkit::Device& device, const char* name) {
  return reinterpret_cast<PFN>(vkGetDeviceProcAddr(device.handle(), name));
}

}  // namespace

vkkit::DeviceOptions RayDevice() {
  static VkPhysicalDeviceRayTracingPipelineFeaturesKHR pipelines{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  pipelines.rayTracingPipeline = VK_TRUE;
  vkkit::DeviceOptions options;
  options.extensions = {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  options.features = &pipelines;
  return options;
}

vkkit::DeviceOptions RayDrawDevice() {
  static VkPhysicalDeviceFeatures2 core{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  core.features.fragmentStoresAndAtomics = VK_TRUE;
  vkkit::DeviceOptions options = RayDevice();
  core.pNext = options.features;
  options.features = &core;
  return options;
}

struct RayProgram::Writes {
  Writes(const RayProgram& p, VkAccelerationStructureKHR structure) : as(structure) {
    as_info.accelerationStructureCount = 1;
    as_info.pAccelerationStructures = &as;
    buffer_info = {p.output_.buffer, 0, VK_WHOLE_SIZE};
    writes[0] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET,        &as_info, p.set_,  0,      0, 1,
                 VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, nullptr,  nullptr, nullptr};
    writes[1] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, p.set_,       1,      0, 1,
                 VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,      nullptr, &buffer_info, nullptr};
  }
  Writes(const Writes&) = delete;
  Writes& operator=(const Writes&) = delete;
  VkAccelerationStructureKHR as;
  VkWriteDescriptorSetAccelerationStructureKHR as_info{
      VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  VkDescriptorBufferInfo buffer_info{};
  VkWriteDescriptorSet writes[2];
};

RayProgram::RayProgram(vkkit::Device& device, Kind kind, bool push) : device_(device), kind_(kind) {
  const VkDevice d = device.handle();
  const VkShaderStageFlags stage = kind == Kind::kRayQuery ? VK_SHADER_STAGE_COMPUTE_BIT
                                   : kind == Kind::kDraw   ? VK_SHADER_STAGE_FRAGMENT_BIT
                                                           : VK_SHADER_STAGE_RAYGEN_BIT_KHR;
  const VkDescriptorSetLayoutBinding bindings[2] = {
      {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, stage, nullptr},
      {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stage, nullptr}};
  VkDescriptorSetLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  layout_info.flags = push ? VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR : 0;
  layout_info.bindingCount = 2;
  layout_info.pBindings = bindings;
  vkkit::Check(vkCreateDescriptorSetLayout(d, &layout_info, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
  VkPipelineLayoutCreateInfo pipeline_layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pipeline_layout_info.setLayoutCount = 1;
  pipeline_layout_info.pSetLayouts = &set_layout_;
  vkkit::Check(vkCreatePipelineLayout(d, &pipeline_layout_info, nullptr, &layout_), "vkCreatePipelineLayout");
  output_ = device.CreateBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (kind == Kind::kRayQuery) {
    MakeComputePipeline();
  } else if (kind == Kind::kDraw) {
    MakeGraphicsPipeline();
  } else {
    MakeRayTracingPipeline();
  }
  if (push) return;
  const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 4},
                                         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4}};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 2;
  pool_info.poolSizeCount = 2;
  pool_info.pPoolSizes = sizes;
  vkkit::Check(vkCreateDescriptorPool(d, &pool_info, nullptr, &pool_), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = pool_;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &set_layout_;
  vkkit::Check(vkAllocateDescriptorSets(d, &alloc, &set_), "vkAllocateDescriptorSets");
}

RayProgram::~RayProgram() {
  const VkDevice d = device_.handle();
  if (pool_) vkDestroyDescriptorPool(d, pool_, nullptr);
  vkDestroyPipeline(d, pipeline_, nullptr);
  vkDestroyPipelineLayout(d, layout_, nullptr);
  vkDestroyDescriptorSetLayout(d, set_layout_, nullptr);
  device_.Destroy(output_);
  if (sbt_.buffer) device_.Destroy(sbt_);
  if (framebuffer_) vkDestroyFramebuffer(d, framebuffer_, nullptr);
  if (render_pass_) vkDestroyRenderPass(d, render_pass_, nullptr);
}

void RayProgram::Write(VkAccelerationStructureKHR structure) {
  const Writes w(*this, structure);
  vkUpdateDescriptorSets(device_.handle(), 2, w.writes, 0, nullptr);
}

void RayProgram::WriteWithTemplate(VkAccelerationStructureKHR structure) {
  // The template's data: the structure's handle, then the output buffer's descriptor.
  struct Data {
    VkAccelerationStructureKHR structure;
    VkDescriptorBufferInfo output;
  } data{structure, {output_.buffer, 0, VK_WHOLE_SIZE}};
  const VkDescriptorUpdateTemplateEntry entries[2] = {
      {0, 0, 1, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, offsetof(Data, structure), sizeof(Data)},
      {1, 0, 1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, offsetof(Data, output), sizeof(Data)}};
  VkDescriptorUpdateTemplateCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_UPDATE_TEMPLATE_CREATE_INFO};
  info.descriptorUpdateEntryCount = 2;
  info.pDescriptorUpdateEntries = entries;
  info.templateType = VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET;
  info.descriptorSetLayout = set_layout_;
  VkDescriptorUpdateTemplate update_template = VK_NULL_HANDLE;
  vkkit::Check(vkCreateDescriptorUpdateTemplate(device_.handle(), &info, nullptr, &update_template),
               "vkCreateDescriptorUpdateTemplate");
  vkUpdateDescriptorSetWithTemplate(device_.handle(), set_, update_template, &data);
  vkDestroyDescriptorUpdateTemplate(device_.handle(), update_template, nullptr);
}

void RayProgram::Record(VkCommandBuffer cb, VkAccelerationStructureKHR pushed) {
  const VkPipelineBindPoint point = bind_point();
  vkCmdBindPipeline(cb, point, pipeline_);
  if (set_) {
    vkCmdBindDescriptorSets(cb, point, layout_, 0, 1, &set_, 0, nullptr);
  } else {
    const Writes w(*this, pushed);
    Proc<PFN_vkCmdPushDescriptorSetKHR>(device_, "vkCmdPushDescriptorSetKHR")(cb, point, layout_, 0, 2, w.writes);
  }
  if (kind_ == Kind::kRayQuery) {
    vkCmdDispatch(cb, 1, 1, 1);
    return;
  }
  if (kind_ == Kind::kDraw) {
    VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    begin.renderPass = render_pass_;
    begin.framebuffer = framebuffer_;
    begin.renderArea.extent = {1, 1};
    vkCmdBeginRenderPass(cb, &begin, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdDraw(cb, 3, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    return;
  }
  const VkStridedDeviceAddressRegionKHR none{};
  Proc<PFN_vkCmdTraceRaysKHR>(device_, "vkCmdTraceRaysKHR")(cb, &raygen_, &miss_, &none, &none, 1, 1, 1);
}

void RayProgram::BarrierAfterBuild(VkCommandBuffer cb) const {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
  const VkPipelineStageFlags stage = kind_ == Kind::kRayQuery ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT
                                     : kind_ == Kind::kDraw   ? VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT
                                                              : VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, stage, 0, 1, &barrier, 0, nullptr, 0,
                       nullptr);
}

void RayProgram::MakeComputePipeline() {
  const VkShaderModule module = MakeModule(device_.handle(), kRayQueryComp, sizeof(kRayQueryComp));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.layout = layout_;
  vkkit::Check(vkCreateComputePipelines(device_.handle(), VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_),
               "vkCreateComputePipelines");
  vkDestroyShaderModule(device_.handle(), module, nullptr);  // the pipeline keeps what it needs
}

void RayProgram::MakeGraphicsPipeline() {
  const VkDevice d = device_.handle();
  // A render pass and a 1x1 framebuffer without attachments: the fragment shader's one invocation writes the buffer.
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  VkRenderPassCreateInfo pass{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  pass.subpassCount = 1;
  pass.pSubpasses = &subpass;
  vkkit::Check(vkCreateRenderPass(d, &pass, nullptr, &render_pass_), "vkCreateRenderPass");
  VkFramebufferCreateInfo framebuffer{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  framebuffer.renderPass = render_pass_;
  framebuffer.width = framebuffer.height = framebuffer.layers = 1;
  vkkit::Check(vkCreateFramebuffer(d, &framebuffer, nullptr, &framebuffer_), "vkCreateFramebuffer");

  const VkShaderModule vert = MakeModule(d, kDrawRayVert, sizeof(kDrawRayVert));
  const VkShaderModule frag = MakeModule(d, kDrawRayFrag, sizeof(kDrawRayFrag));
  VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                               {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = vert;
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = frag;
  stages[1].pName = "main";
  VkPipelineVertexInputStateCreateInfo vertex_input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  const VkViewport viewport{0, 0, 1, 1, 0, 1};
  const VkRect2D scissor{{0, 0}, {1, 1}};
  VkPipelineViewportStateCreateInfo viewports{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewports.viewportCount = 1;
  viewports.pViewports = &viewport;
  viewports.scissorCount = 1;
  viewports.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.lineWidth = 1;
  VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &vertex_input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewports;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.layout = layout_;
  info.renderPass = render_pass_;
  vkkit::Check(vkCreateGraphicsPipelines(d, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_),
               "vkCreateGraphicsPipelines");
  vkDestroyShaderModule(d, vert, nullptr);
  vkDestroyShaderModule(d, frag, nullptr);
}

void RayProgram::MakeRayTracingPipeline() {
  const VkDevice d = device_.handle();
  const VkShaderModule raygen = MakeModule(d, kTraceRayRgen, sizeof(kTraceRayRgen));
  const VkShaderModule miss = MakeModule(d, kTraceMissRmiss, sizeof(kTraceMissRmiss));
  VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                               {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_RAYGEN_BIT_KHR;
  stages[0].module = raygen;
  stages[0].pName = "main";
  stages[1].stage = VK_SHADER_STAGE_MISS_BIT_KHR;
  stages[1].module = miss;
  stages[1].pName = "main";
  VkRayTracingShaderGroupCreateInfoKHR groups[2] = {{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR},
                                                    {VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR}};
  for (uint32_t i = 0; i < 2; ++i) {
    groups[i].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    groups[i].generalShader = i;
    groups[i].closestHitShader = groups[i].anyHitShader = groups[i].intersectionShader = VK_SHADER_UNUSED_KHR;
  }
  VkRayTracingPipelineCreateInfoKHR info{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
  info.stageCount = 2;
  info.pStages = stages;
  info.groupCount = 2;
  info.pGroups = groups;
  info.maxPipelineRayRecursionDepth = 1;
  info.layout = layout_;
  vkkit::Check(Proc<PFN_vkCreateRayTracingPipelinesKHR>(device_, "vkCreateRayTracingPipelinesKHR")(
                   d, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_),
               "vkCreateRayTracingPipelinesKHR");
  vkDestroyShaderModule(d, raygen, nullptr);
  vkDestroyShaderModule(d, miss, nullptr);

  // The shader binding table: the raygen and miss handles, each at a base-aligned offset.
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rt{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &rt};
  vkGetPhysicalDeviceProperties2(device_.physical_device(), &props);
  const uint32_t handle_size = rt.shaderGroupHandleSize;
  const VkDeviceSize align = rt.shaderGroupBaseAlignment;
  const VkDeviceSize stride = (handle_size + align - 1) / align * align;
  std::vector<uint8_t> handles(2 * handle_size);
  vkkit::Check(Proc<PFN_vkGetRayTracingShaderGroupHandlesKHR>(device_, "vkGetRayTracingShaderGroupHandlesKHR")(
                   d, pipeline_, 0, 2, handles.size(), handles.data()),
               "vkGetRayTracingShaderGroupHandlesKHR");
  sbt_ = device_.CreateBuffer(2 * stride + align, VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR);
  const VkDeviceAddress base = (sbt_.address + align - 1) / align * align;
  auto* bytes = static_cast<uint8_t*>(sbt_.mapped) + (base - sbt_.address);
  std::memcpy(bytes, handles.data(), handle_size);
  std::memcpy(bytes + stride, handles.data() + handle_size, handle_size);
  raygen_ = {base, stride, stride};
  miss_ = {base + stride, stride, stride};
}

}  // namespace asval_test

namespace asval_test {

vkkit::DeviceOptions RayDescriptorBufferDevice() {
  static VkPhysicalDeviceDescriptorBufferFeaturesEXT buffers{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DESCRIPTOR_BUFFER_FEATURES_EXT};
  buffers.descriptorBuffer = VK_TRUE;
  vkkit::DeviceOptions options = RayDevice();
  buffers.pNext = options.features;
  options.features = &buffers;
  options.extensions.push_back(VK_EXT_DESCRIPTOR_BUFFER_EXTENSION_NAME);
  return options;
}

DescriptorBufferRayQuery::DescriptorBufferRayQuery(vkkit::Device& device) : device_(device) {
  const VkDevice d = device.handle();
  VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &properties_};
  vkGetPhysicalDeviceProperties2(device.physical_device(), &properties);
  const VkDescriptorSetLayoutBinding bindings[2] = {
      {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr}};
  VkDescriptorSetLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  layout_info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_DESCRIPTOR_BUFFER_BIT_EXT;
  layout_info.bindingCount = 2;
  layout_info.pBindings = bindings;
  vkkit::Check(vkCreateDescriptorSetLayout(d, &layout_info, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
  const auto offset_of =
      Proc<PFN_vkGetDescriptorSetLayoutBindingOffsetEXT>(device, "vkGetDescriptorSetLayoutBindingOffsetEXT");
  const auto size_of = Proc<PFN_vkGetDescriptorSetLayoutSizeEXT>(device, "vkGetDescriptorSetLayoutSizeEXT");
  offset_of(d, set_layout_, 0, &structure_offset_);
  offset_of(d, set_layout_, 1, &output_offset_);
  VkDeviceSize layout_size = 0;
  size_of(d, set_layout_, &layout_size);
  VkPipelineLayoutCreateInfo pipeline_layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pipeline_layout_info.setLayoutCount = 1;
  pipeline_layout_info.pSetLayouts = &set_layout_;
  vkkit::Check(vkCreatePipelineLayout(d, &pipeline_layout_info, nullptr, &layout_), "vkCreatePipelineLayout");
  descriptors_ = device.CreateBuffer(layout_size, VK_BUFFER_USAGE_RESOURCE_DESCRIPTOR_BUFFER_BIT_EXT);
  output_ = device.CreateBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const VkShaderModule module = MakeModule(d, kRayQueryComp, sizeof(kRayQueryComp));
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.flags = VK_PIPELINE_CREATE_DESCRIPTOR_BUFFER_BIT_EXT;
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.layout = layout_;
  vkkit::Check(vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_), "vkCreateComputePipelines");
  vkDestroyShaderModule(d, module, nullptr);
}

DescriptorBufferRayQuery::~DescriptorBufferRayQuery() {
  const VkDevice d = device_.handle();
  vkDestroyPipeline(d, pipeline_, nullptr);
  vkDestroyPipelineLayout(d, layout_, nullptr);
  vkDestroyDescriptorSetLayout(d, set_layout_, nullptr);
  device_.Destroy(descriptors_);
  device_.Destroy(output_);
}

void DescriptorBufferRayQuery::Write(VkDeviceAddress address) {
  const auto get = Proc<PFN_vkGetDescriptorEXT>(device_, "vkGetDescriptorEXT");
  auto* bytes = static_cast<unsigned char*>(descriptors_.mapped);
  VkDescriptorGetInfoEXT info{VK_STRUCTURE_TYPE_DESCRIPTOR_GET_INFO_EXT};
  info.type = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  info.data.accelerationStructure = address;
  get(device_.handle(), &info, properties_.accelerationStructureDescriptorSize, bytes + structure_offset_);
  const VkDescriptorAddressInfoEXT output{VK_STRUCTURE_TYPE_DESCRIPTOR_ADDRESS_INFO_EXT, nullptr, output_.address,
                                          output_.size, VK_FORMAT_UNDEFINED};
  info.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  info.data.pStorageBuffer = &output;
  get(device_.handle(), &info, properties_.storageBufferDescriptorSize, bytes + output_offset_);
}

void DescriptorBufferRayQuery::Scribble(unsigned char value) {
  std::memset(static_cast<unsigned char*>(descriptors_.mapped) + structure_offset_, value,
              properties_.accelerationStructureDescriptorSize);
}

void DescriptorBufferRayQuery::Record(VkCommandBuffer cb) {
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  VkDescriptorBufferBindingInfoEXT binding{VK_STRUCTURE_TYPE_DESCRIPTOR_BUFFER_BINDING_INFO_EXT};
  binding.address = descriptors_.address;
  binding.usage = VK_BUFFER_USAGE_RESOURCE_DESCRIPTOR_BUFFER_BIT_EXT;
  Proc<PFN_vkCmdBindDescriptorBuffersEXT>(device_, "vkCmdBindDescriptorBuffersEXT")(cb, 1, &binding);
  const uint32_t index = 0;
  const VkDeviceSize offset = 0;
  Proc<PFN_vkCmdSetDescriptorBufferOffsetsEXT>(device_, "vkCmdSetDescriptorBufferOffsetsEXT")(
      cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &index, &offset);
  vkCmdDispatch(cb, 1, 1, 1);
}

}  // namespace asval_test
