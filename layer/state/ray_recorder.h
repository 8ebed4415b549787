#pragma once
// Family traces (issue 29): the writes of what trace and ray-query work binds (ray_bindings.h, bound_structures.h)
// and the kTrace operations of the commands that read it. Every function does nothing when
// DeviceState::traces_tracked is false; the per-command ones cost one relaxed load while no pipeline of the device
// reads acceleration structures.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <functional>

#include "device_state.h"

namespace asval {

// ---- objects (after a successful downcall) ----
void RecordCreateShaderModule(DeviceState& state, const VkShaderModuleCreateInfo& info, VkShaderModule module);
void RecordDestroyShaderModule(DeviceState& state, VkShaderModule module);
void RecordCreateComputePipelines(DeviceState& state, uint32_t count, const VkComputePipelineCreateInfo* infos,
                                  const VkPipeline* pipelines);
void RecordCreateRayTracingPipelines(DeviceState& state, uint32_t count, const VkRayTracingPipelineCreateInfoKHR* infos,
                                     const VkPipeline* pipelines);
void RecordCreateGraphicsPipelines(DeviceState& state, uint32_t count, const VkGraphicsPipelineCreateInfo* infos,
                                   const VkPipeline* pipelines);
void RecordDestroyPipeline(DeviceState& state, VkPipeline pipeline);
// offset_of(binding): where a descriptor-buffer layout's binding starts (vkGetDescriptorSetLayoutBindingOffsetEXT);
// asked only of layouts created with VK_DESCRIPTOR_SET_LAYOUT_CREATE_DESCRIPTOR_BUFFER_BIT_EXT, for their structure
// bindings; null when the device cannot answer (the layout's descriptors are then not read).
void RecordCreateDescriptorSetLayout(DeviceState& state, const VkDescriptorSetLayoutCreateInfo& info,
                                     VkDescriptorSetLayout layout,
                                     const std::function<VkDeviceSize(uint32_t binding)>& offset_of = nullptr);
void RecordCreatePipelineLayout(DeviceState& state, const VkPipelineLayoutCreateInfo& info, VkPipelineLayout layout);
void RecordDestroyPipelineLayout(DeviceState& state, VkPipelineLayout layout);
// vkGetDescriptorEXT: a structure descriptor's bytes (`size` of them at `bytes`), made from info.
void RecordGetDescriptor(DeviceState& state, const VkDescriptorGetInfoEXT& info, std::size_t size, const void* bytes);
void RecordDestroyDescriptorSetLayout(DeviceState& state, VkDescriptorSetLayout layout);
void RecordCreateDescriptorUpdateTemplate(DeviceState& state, const VkDescriptorUpdateTemplateCreateInfo& info,
                                          VkDescriptorUpdateTemplate update_template);
void RecordDestroyDescriptorUpdateTemplate(DeviceState& state, VkDescriptorUpdateTemplate update_template);
void RecordAllocateDescriptorSets(DeviceState& state, const VkDescriptorSetAllocateInfo& info,
                                  const VkDescriptorSet* sets);
void RecordFreeDescriptorSets(DeviceState& state, uint32_t count, const VkDescriptorSet* sets);
// vkResetDescriptorPool, vkDestroyDescriptorPool.
void RecordResetDescriptorPool(DeviceState& state, VkDescriptorPool pool);
void RecordUpdateDescriptorSets(DeviceState& state, uint32_t write_count, const VkWriteDescriptorSet* writes,
                                uint32_t copy_count, const VkCopyDescriptorSet* copies);
void RecordUpdateDescriptorSetWithTemplate(DeviceState& state, VkDescriptorSet set,
                                           VkDescriptorUpdateTemplate update_template, const void* data);

// ---- commands (after the downcall) ----
void RecordBindPipelineForTraces(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point,
                                 VkPipeline pipeline);
void RecordBindDescriptorSets(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point,
                              uint32_t first_set, uint32_t count, const VkDescriptorSet* sets);
void RecordPushDescriptorSet(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point, uint32_t set,
                             uint32_t write_count, const VkWriteDescriptorSet* writes);
// vkCmdPushDescriptorSetWithTemplateKHR: what it pushes is not read; set number `set` of both bind points (the
// template's bind point is not kept) is not followed until something is bound there again.
void RecordPushDescriptorSetWithTemplate(DeviceState& state, VkCommandBuffer cb, uint32_t set);
void RecordBindDescriptorBuffers(DeviceState& state, VkCommandBuffer cb, uint32_t count,
                                 const VkDescriptorBufferBindingInfoEXT* infos);
void RecordSetDescriptorBufferOffsets(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point,
                                      VkPipelineLayout layout, uint32_t first_set, uint32_t count,
                                      const uint32_t* indices, const VkDeviceSize* offsets);
// vkCmdExecuteCommands: the primary's bindings are undefined afterwards.
void RecordExecuteForTraces(DeviceState& state, VkCommandBuffer primary);
// A trace (command kCmdTraceRays*) or dispatch (kCmdDispatch*).
void RecordTraceCommand(DeviceState& state, VkCommandBuffer cb, OpCommand command);

}  // namespace asval
