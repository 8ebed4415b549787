// Trace and ray-query work (family traces, issue 29): the shader modules and pipelines that read acceleration-structure
// descriptors, the descriptors written into sets, the sets bound, and the traces and dispatches that read them
// (layer/state/ray_recorder.h). Each is passed down unchanged first; the layer records what succeeded. Destroys are
// recorded before the downcall: afterwards another thread may be handed the same handle value.
#include <functional>

#include "layer_data.h"
#include "ray_recorder.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateShaderModule(VkDevice device, const VkShaderModuleCreateInfo* pCreateInfo,
                                                  const VkAllocationCallbacks* pAllocator,
                                                  VkShaderModule* pShaderModule) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateShaderModule(device, pCreateInfo, pAllocator, pShaderModule);
  if (result == VK_SUCCESS && pCreateInfo) RecordCreateShaderModule(data->state, *pCreateInfo, *pShaderModule);
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyShaderModule(VkDevice device, VkShaderModule shaderModule,
                                               const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  RecordDestroyShaderModule(data->state, shaderModule);
  data->dispatch.DestroyShaderModule(device, shaderModule, pAllocator);
}

// A creation that fails may still have created some pipelines (VK_PIPELINE_COMPILE_REQUIRED and others leave the
// rest VK_NULL_HANDLE): every non-null handle is kept.
VKAPI_ATTR VkResult VKAPI_CALL CreateComputePipelines(VkDevice device, VkPipelineCache pipelineCache,
                                                      uint32_t createInfoCount,
                                                      const VkComputePipelineCreateInfo* pCreateInfos,
                                                      const VkAllocationCallbacks* pAllocator, VkPipeline* pPipelines) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateComputePipelines(device, pipelineCache, createInfoCount, pCreateInfos,
                                                                pAllocator, pPipelines);
  if (result >= VK_SUCCESS) RecordCreateComputePipelines(data->state, createInfoCount, pCreateInfos, pPipelines);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateGraphicsPipelines(VkDevice device, VkPipelineCache pipelineCache,
                                                       uint32_t createInfoCount,
                                                       const VkGraphicsPipelineCreateInfo* pCreateInfos,
                                                       const VkAllocationCallbacks* pAllocator,
                                                       VkPipeline* pPipelines) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateGraphicsPipelines(device, pipelineCache, createInfoCount, pCreateInfos,
                                                                 pAllocator, pPipelines);
  if (result >= VK_SUCCESS) RecordCreateGraphicsPipelines(data->state, createInfoCount, pCreateInfos, pPipelines);
  return result;
}

// A deferred creation (VK_OPERATION_DEFERRED_KHR) writes its handles when the operation completes: not followed.
VKAPI_ATTR VkResult VKAPI_CALL CreateRayTracingPipelinesKHR(VkDevice device, VkDeferredOperationKHR deferredOperation,
                                                            VkPipelineCache pipelineCache, uint32_t createInfoCount,
                                                            const VkRayTracingPipelineCreateInfoKHR* pCreateInfos,
                                                            const VkAllocationCallbacks* pAllocator,
                                                            VkPipeline* pPipelines) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateRayTracingPipelinesKHR(
      device, deferredOperation, pipelineCache, createInfoCount, pCreateInfos, pAllocator, pPipelines);
  if (result == VK_SUCCESS || result == VK_PIPELINE_COMPILE_REQUIRED) {
    RecordCreateRayTracingPipelines(data->state, createInfoCount, pCreateInfos, pPipelines);
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyPipeline(VkDevice device, VkPipeline pipeline,
                                           const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  RecordDestroyPipeline(data->state, pipeline);
  data->dispatch.DestroyPipeline(device, pipeline, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDescriptorSetLayout(VkDevice device,
                                                         const VkDescriptorSetLayoutCreateInfo* pCreateInfo,
                                                         const VkAllocationCallbacks* pAllocator,
                                                         VkDescriptorSetLayout* pSetLayout) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateDescriptorSetLayout(device, pCreateInfo, pAllocator, pSetLayout);
  if (result != VK_SUCCESS || !pCreateInfo) return result;
  // A descriptor-buffer layout's binding offsets, asked of the driver (the app may ask the same).
  const PFN_vkGetDescriptorSetLayoutBindingOffsetEXT offset = data->dispatch.GetDescriptorSetLayoutBindingOffsetEXT;
  const VkDescriptorSetLayout layout = *pSetLayout;
  const auto offset_of = [&](uint32_t binding) {
    VkDeviceSize at = 0;
    offset(device, layout, binding, &at);
    return at;
  };
  RecordCreateDescriptorSetLayout(data->state, *pCreateInfo, layout,
                                  offset ? std::function<VkDeviceSize(uint32_t)>(offset_of) : nullptr);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL CreatePipelineLayout(VkDevice device, const VkPipelineLayoutCreateInfo* pCreateInfo,
                                                    const VkAllocationCallbacks* pAllocator,
                                                    VkPipelineLayout* pPipelineLayout) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreatePipelineLayout(device, pCreateInfo, pAllocator, pPipelineLayout);
  if (result == VK_SUCCESS && pCreateInfo) RecordCreatePipelineLayout(data->state, *pCreateInfo, *pPipelineLayout);
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyPipelineLayout(VkDevice device, VkPipelineLayout pipelineLayout,
                                                 const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  RecordDestroyPipelineLayout(data->state, pipelineLayout);
  data->dispatch.DestroyPipelineLayout(device, pipelineLayout, pAllocator);
}

VKAPI_ATTR void VKAPI_CALL GetDescriptorEXT(VkDevice device, const VkDescriptorGetInfoEXT* pDescriptorInfo,
                                            size_t dataSize, void* pDescriptor) {
  DeviceData* data = GetDeviceData(device);
  data->dispatch.GetDescriptorEXT(device, pDescriptorInfo, dataSize, pDescriptor);
  if (pDescriptorInfo && pDescriptor) RecordGetDescriptor(data->state, *pDescriptorInfo, dataSize, pDescriptor);
}

VKAPI_ATTR void VKAPI_CALL DestroyDescriptorSetLayout(VkDevice device, VkDescriptorSetLayout descriptorSetLayout,
                                                      const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  RecordDestroyDescriptorSetLayout(data->state, descriptorSetLayout);
  data->dispatch.DestroyDescriptorSetLayout(device, descriptorSetLayout, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDescriptorUpdateTemplate(VkDevice device,
                                                              const VkDescriptorUpdateTemplateCreateInfo* pCreateInfo,
                                                              const VkAllocationCallbacks* pAllocator,
                                                              VkDescriptorUpdateTemplate* pDescriptorUpdateTemplate) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result =
      data->dispatch.CreateDescriptorUpdateTemplate(device, pCreateInfo, pAllocator, pDescriptorUpdateTemplate);
  if (result == VK_SUCCESS && pCreateInfo) {
    RecordCreateDescriptorUpdateTemplate(data->state, *pCreateInfo, *pDescriptorUpdateTemplate);
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyDescriptorUpdateTemplate(VkDevice device,
                                                           VkDescriptorUpdateTemplate descriptorUpdateTemplate,
                                                           const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  RecordDestroyDescriptorUpdateTemplate(data->state, descriptorUpdateTemplate);
  data->dispatch.DestroyDescriptorUpdateTemplate(device, descriptorUpdateTemplate, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL AllocateDescriptorSets(VkDevice device, const VkDescriptorSetAllocateInfo* pAllocateInfo,
                                                      VkDescriptorSet* pDescriptorSets) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.AllocateDescriptorSets(device, pAllocateInfo, pDescriptorSets);
  if (result == VK_SUCCESS && pAllocateInfo) RecordAllocateDescriptorSets(data->state, *pAllocateInfo, pDescriptorSets);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL FreeDescriptorSets(VkDevice device, VkDescriptorPool descriptorPool,
                                                  uint32_t descriptorSetCount, const VkDescriptorSet* pDescriptorSets) {
  DeviceData* data = GetDeviceData(device);
  RecordFreeDescriptorSets(data->state, descriptorSetCount, pDescriptorSets);
  return data->dispatch.FreeDescriptorSets(device, descriptorPool, descriptorSetCount, pDescriptorSets);
}

VKAPI_ATTR VkResult VKAPI_CALL ResetDescriptorPool(VkDevice device, VkDescriptorPool descriptorPool,
                                                   VkDescriptorPoolResetFlags flags) {
  DeviceData* data = GetDeviceData(device);
  RecordResetDescriptorPool(data->state, descriptorPool);
  return data->dispatch.ResetDescriptorPool(device, descriptorPool, flags);
}

VKAPI_ATTR void VKAPI_CALL DestroyDescriptorPool(VkDevice device, VkDescriptorPool descriptorPool,
                                                 const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  if (descriptorPool) RecordResetDescriptorPool(data->state, descriptorPool);
  data->dispatch.DestroyDescriptorPool(device, descriptorPool, pAllocator);
}

VKAPI_ATTR void VKAPI_CALL UpdateDescriptorSets(VkDevice device, uint32_t descriptorWriteCount,
                                                const VkWriteDescriptorSet* pDescriptorWrites,
                                                uint32_t descriptorCopyCount,
                                                const VkCopyDescriptorSet* pDescriptorCopies) {
  DeviceData* data = GetDeviceData(device);
  data->dispatch.UpdateDescriptorSets(device, descriptorWriteCount, pDescriptorWrites, descriptorCopyCount,
                                      pDescriptorCopies);
  RecordUpdateDescriptorSets(data->state, descriptorWriteCount, pDescriptorWrites, descriptorCopyCount,
                             pDescriptorCopies);
}

VKAPI_ATTR void VKAPI_CALL UpdateDescriptorSetWithTemplate(VkDevice device, VkDescriptorSet descriptorSet,
                                                           VkDescriptorUpdateTemplate descriptorUpdateTemplate,
                                                           const void* pData) {
  DeviceData* data = GetDeviceData(device);
  data->dispatch.UpdateDescriptorSetWithTemplate(device, descriptorSet, descriptorUpdateTemplate, pData);
  RecordUpdateDescriptorSetWithTemplate(data->state, descriptorSet, descriptorUpdateTemplate, pData);
}

VKAPI_ATTR void VKAPI_CALL CmdBindDescriptorSets(VkCommandBuffer commandBuffer, VkPipelineBindPoint pipelineBindPoint,
                                                 VkPipelineLayout layout, uint32_t firstSet,
                                                 uint32_t descriptorSetCount, const VkDescriptorSet* pDescriptorSets,
                                                 uint32_t dynamicOffsetCount, const uint32_t* pDynamicOffsets) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdBindDescriptorSets(commandBuffer, pipelineBindPoint, layout, firstSet, descriptorSetCount,
                                       pDescriptorSets, dynamicOffsetCount, pDynamicOffsets);
  RecordBindDescriptorSets(data->state, commandBuffer, pipelineBindPoint, firstSet, descriptorSetCount,
                           pDescriptorSets);
}

VKAPI_ATTR void VKAPI_CALL CmdBindDescriptorBuffersEXT(VkCommandBuffer commandBuffer, uint32_t bufferCount,
                                                       const VkDescriptorBufferBindingInfoEXT* pBindingInfos) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdBindDescriptorBuffersEXT(commandBuffer, bufferCount, pBindingInfos);
  RecordBindDescriptorBuffers(data->state, commandBuffer, bufferCount, pBindingInfos);
}

VKAPI_ATTR void VKAPI_CALL CmdSetDescriptorBufferOffsetsEXT(VkCommandBuffer commandBuffer,
                                                            VkPipelineBindPoint pipelineBindPoint,
                                                            VkPipelineLayout layout, uint32_t firstSet,
                                                            uint32_t setCount, const uint32_t* pBufferIndices,
                                                            const VkDeviceSize* pOffsets) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdSetDescriptorBufferOffsetsEXT(commandBuffer, pipelineBindPoint, layout, firstSet, setCount,
                                                  pBufferIndices, pOffsets);
  RecordSetDescriptorBufferOffsets(data->state, commandBuffer, pipelineBindPoint, layout, firstSet, setCount,
                                   pBufferIndices, pOffsets);
}

VKAPI_ATTR void VKAPI_CALL CmdPushDescriptorSetKHR(VkCommandBuffer commandBuffer, VkPipelineBindPoint pipelineBindPoint,
                                                   VkPipelineLayout layout, uint32_t set, uint32_t descriptorWriteCount,
                                                   const VkWriteDescriptorSet* pDescriptorWrites) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdPushDescriptorSetKHR(commandBuffer, pipelineBindPoint, layout, set, descriptorWriteCount,
                                         pDescriptorWrites);
  RecordPushDescriptorSet(data->state, commandBuffer, pipelineBindPoint, set, descriptorWriteCount, pDescriptorWrites);
}

VKAPI_ATTR void VKAPI_CALL CmdPushDescriptorSetWithTemplateKHR(VkCommandBuffer commandBuffer,
                                                               VkDescriptorUpdateTemplate descriptorUpdateTemplate,
                                                               VkPipelineLayout layout, uint32_t set,
                                                               const void* pData) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdPushDescriptorSetWithTemplateKHR(commandBuffer, descriptorUpdateTemplate, layout, set, pData);
  RecordPushDescriptorSetWithTemplate(data->state, commandBuffer, set);
}

VKAPI_ATTR void VKAPI_CALL CmdDispatch(VkCommandBuffer commandBuffer, uint32_t groupCountX, uint32_t groupCountY,
                                       uint32_t groupCountZ) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDispatch(commandBuffer, groupCountX, groupCountY, groupCountZ);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDispatch);
}

VKAPI_ATTR void VKAPI_CALL CmdDispatchIndirect(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDispatchIndirect(commandBuffer, buffer, offset);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDispatchIndirect);
}

VKAPI_ATTR void VKAPI_CALL CmdDispatchBase(VkCommandBuffer commandBuffer, uint32_t baseGroupX, uint32_t baseGroupY,
                                           uint32_t baseGroupZ, uint32_t groupCountX, uint32_t groupCountY,
                                           uint32_t groupCountZ) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDispatchBase(commandBuffer, baseGroupX, baseGroupY, baseGroupZ, groupCountX, groupCountY,
                                 groupCountZ);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDispatchBase);
}

VKAPI_ATTR void VKAPI_CALL CmdTraceRaysKHR(VkCommandBuffer commandBuffer,
                                           const VkStridedDeviceAddressRegionKHR* pRaygenShaderBindingTable,
                                           const VkStridedDeviceAddressRegionKHR* pMissShaderBindingTable,
                                           const VkStridedDeviceAddressRegionKHR* pHitShaderBindingTable,
                                           const VkStridedDeviceAddressRegionKHR* pCallableShaderBindingTable,
                                           uint32_t width, uint32_t height, uint32_t depth) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdTraceRaysKHR(commandBuffer, pRaygenShaderBindingTable, pMissShaderBindingTable,
                                 pHitShaderBindingTable, pCallableShaderBindingTable, width, height, depth);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdTraceRays);
}

VKAPI_ATTR void VKAPI_CALL CmdTraceRaysIndirectKHR(VkCommandBuffer commandBuffer,
                                                   const VkStridedDeviceAddressRegionKHR* pRaygenShaderBindingTable,
                                                   const VkStridedDeviceAddressRegionKHR* pMissShaderBindingTable,
                                                   const VkStridedDeviceAddressRegionKHR* pHitShaderBindingTable,
                                                   const VkStridedDeviceAddressRegionKHR* pCallableShaderBindingTable,
                                                   VkDeviceAddress indirectDeviceAddress) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdTraceRaysIndirectKHR(commandBuffer, pRaygenShaderBindingTable, pMissShaderBindingTable,
                                         pHitShaderBindingTable, pCallableShaderBindingTable, indirectDeviceAddress);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdTraceRaysIndirect);
}

VKAPI_ATTR void VKAPI_CALL CmdTraceRaysIndirect2KHR(VkCommandBuffer commandBuffer,
                                                    VkDeviceAddress indirectDeviceAddress) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdTraceRaysIndirect2KHR(commandBuffer, indirectDeviceAddress);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdTraceRaysIndirect2);
}

// Draws: ray queries in graphics and mesh pipelines.
VKAPI_ATTR void VKAPI_CALL CmdDraw(VkCommandBuffer commandBuffer, uint32_t vertexCount, uint32_t instanceCount,
                                   uint32_t firstVertex, uint32_t firstInstance) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDraw(commandBuffer, vertexCount, instanceCount, firstVertex, firstInstance);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDraw);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndexed(VkCommandBuffer commandBuffer, uint32_t indexCount, uint32_t instanceCount,
                                          uint32_t firstIndex, int32_t vertexOffset, uint32_t firstInstance) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawIndexed(commandBuffer, indexCount, instanceCount, firstIndex, vertexOffset, firstInstance);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawIndexed);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndirect(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset,
                                           uint32_t drawCount, uint32_t stride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawIndirect(commandBuffer, buffer, offset, drawCount, stride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawIndirect);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndexedIndirect(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset,
                                                  uint32_t drawCount, uint32_t stride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawIndexedIndirect(commandBuffer, buffer, offset, drawCount, stride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawIndexedIndirect);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndirectCount(VkCommandBuffer commandBuffer, VkBuffer buffer, VkDeviceSize offset,
                                                VkBuffer countBuffer, VkDeviceSize countBufferOffset,
                                                uint32_t maxDrawCount, uint32_t stride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawIndirectCount(commandBuffer, buffer, offset, countBuffer, countBufferOffset, maxDrawCount,
                                      stride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawIndirectCount);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndexedIndirectCount(VkCommandBuffer commandBuffer, VkBuffer buffer,
                                                       VkDeviceSize offset, VkBuffer countBuffer,
                                                       VkDeviceSize countBufferOffset, uint32_t maxDrawCount,
                                                       uint32_t stride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawIndexedIndirectCount(commandBuffer, buffer, offset, countBuffer, countBufferOffset,
                                             maxDrawCount, stride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawIndexedIndirectCount);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawMultiEXT(VkCommandBuffer commandBuffer, uint32_t drawCount,
                                           const VkMultiDrawInfoEXT* pVertexInfo, uint32_t instanceCount,
                                           uint32_t firstInstance, uint32_t stride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawMultiEXT(commandBuffer, drawCount, pVertexInfo, instanceCount, firstInstance, stride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawMultiEXT);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawMultiIndexedEXT(VkCommandBuffer commandBuffer, uint32_t drawCount,
                                                  const VkMultiDrawIndexedInfoEXT* pIndexInfo, uint32_t instanceCount,
                                                  uint32_t firstInstance, uint32_t stride,
                                                  const int32_t* pVertexOffset) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawMultiIndexedEXT(commandBuffer, drawCount, pIndexInfo, instanceCount, firstInstance, stride,
                                        pVertexOffset);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawMultiIndexedEXT);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawIndirectByteCountEXT(VkCommandBuffer commandBuffer, uint32_t instanceCount,
                                                       uint32_t firstInstance, VkBuffer counterBuffer,
                                                       VkDeviceSize counterBufferOffset, uint32_t counterOffset,
                                                       uint32_t vertexStride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawIndirectByteCountEXT(commandBuffer, instanceCount, firstInstance, counterBuffer,
                                             counterBufferOffset, counterOffset, vertexStride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawIndirectByteCountEXT);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawMeshTasksEXT(VkCommandBuffer commandBuffer, uint32_t groupCountX,
                                               uint32_t groupCountY, uint32_t groupCountZ) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawMeshTasksEXT(commandBuffer, groupCountX, groupCountY, groupCountZ);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawMeshTasksEXT);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawMeshTasksIndirectEXT(VkCommandBuffer commandBuffer, VkBuffer buffer,
                                                       VkDeviceSize offset, uint32_t drawCount, uint32_t stride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawMeshTasksIndirectEXT(commandBuffer, buffer, offset, drawCount, stride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawMeshTasksIndirectEXT);
}

VKAPI_ATTR void VKAPI_CALL CmdDrawMeshTasksIndirectCountEXT(VkCommandBuffer commandBuffer, VkBuffer buffer,
                                                            VkDeviceSize offset, VkBuffer countBuffer,
                                                            VkDeviceSize countBufferOffset, uint32_t maxDrawCount,
                                                            uint32_t stride) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdDrawMeshTasksIndirectCountEXT(commandBuffer, buffer, offset, countBuffer, countBufferOffset,
                                                  maxDrawCount, stride);
  RecordTraceCommand(data->state, commandBuffer, OpCommand::kCmdDrawMeshTasksIndirectCountEXT);
}

}  // namespace asval::hooks
