// VK_NV_ray_tracing's acceleration structures: their objects (created with their build parameters, bound to memory
// by vkBindAccelerationStructureMemoryNV) and their build, copy and property-query commands. The record-time rules
// (layer/checks/nv_ray_tracing.h), then the operation for the build history, shared with the KHR commands by
// handle value (layer/state/nv_structures.h) and judged at submission (update_rules.h).
#include "history_recorder.h"
#include "layer_data.h"
#include "nv_ray_tracing.h"
#include "nv_structures.h"
#include "vk_intercepts.h"
#include "withhold.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateAccelerationStructureNV(VkDevice device,
                                                             const VkAccelerationStructureCreateInfoNV* pCreateInfo,
                                                             const VkAllocationCallbacks* pAllocator,
                                                             VkAccelerationStructureNV* pAccelerationStructure) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result =
      data->dispatch.CreateAccelerationStructureNV(device, pCreateInfo, pAllocator, pAccelerationStructure);
  if (result == VK_SUCCESS && pCreateInfo) {
    RecordCreateAccelerationStructureNV(data->state, data->dispatch, device, *pCreateInfo, *pAccelerationStructure);
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyAccelerationStructureNV(VkDevice device,
                                                          VkAccelerationStructureNV accelerationStructure,
                                                          const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  // Before the downcall: afterwards the handle value may be handed out again by another thread.
  if (accelerationStructure) {
    RecordDestroyAccelerationStructureNV(data->state, accelerationStructure);
    data->reporter->ForgetObjectName(Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_NV, accelerationStructure));
  }
  data->dispatch.DestroyAccelerationStructureNV(device, accelerationStructure, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL BindAccelerationStructureMemoryNV(
    VkDevice device, uint32_t bindInfoCount, const VkBindAccelerationStructureMemoryInfoNV* pBindInfos) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.BindAccelerationStructureMemoryNV(device, bindInfoCount, pBindInfos);
  if (result == VK_SUCCESS && pBindInfos) {
    for (uint32_t i = 0; i < bindInfoCount; ++i) RecordBindAccelerationStructureMemoryNV(data->state, pBindInfos[i]);
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructureNV(VkCommandBuffer commandBuffer,
                                                           const VkAccelerationStructureInfoNV* pInfo,
                                                           VkBuffer instanceData, VkDeviceSize instanceOffset,
                                                           VkBool32 update, VkAccelerationStructureNV dst,
                                                           VkAccelerationStructureNV src, VkBuffer scratch,
                                                           VkDeviceSize scratchOffset) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx = MakeCheckContext(*data);
  const ProtectScope protect(data->reporter->protects());
  const NvBuildArgs args{pInfo, instanceData, update, dst, src, scratch, scratchOffset};
  if (ValidateBuildNV(ctx, commandBuffer, args)) {
    return WithholdRecordedCommand(*data, "vkCmdBuildAccelerationStructureNV", commandBuffer, protect);
  }
  data->dispatch.CmdBuildAccelerationStructureNV(commandBuffer, pInfo, instanceData, instanceOffset, update, dst, src,
                                                 scratch, scratchOffset);
  if (pInfo) RecordCmdBuildNV(data->state, commandBuffer, *pInfo, update == VK_TRUE, dst, src);
}

VKAPI_ATTR void VKAPI_CALL CmdCopyAccelerationStructureNV(VkCommandBuffer commandBuffer, VkAccelerationStructureNV dst,
                                                          VkAccelerationStructureNV src,
                                                          VkCopyAccelerationStructureModeKHR mode) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx = MakeCheckContext(*data);
  const ProtectScope protect(data->reporter->protects());
  if (ctx.Enabled(kCheckCopies) && ValidateCopyNV(ctx, commandBuffer, dst, src, mode)) {
    return WithholdRecordedCommand(*data, "vkCmdCopyAccelerationStructureNV", commandBuffer, protect);
  }
  data->dispatch.CmdCopyAccelerationStructureNV(commandBuffer, dst, src, mode);
  RecordCmdCopyNV(data->state, commandBuffer, dst, src, mode);
}

VKAPI_ATTR void VKAPI_CALL
CmdWriteAccelerationStructuresPropertiesNV(VkCommandBuffer commandBuffer, uint32_t accelerationStructureCount,
                                           const VkAccelerationStructureNV* pAccelerationStructures,
                                           VkQueryType queryType, VkQueryPool queryPool, uint32_t firstQuery) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx = MakeCheckContext(*data);
  const char* function = "vkCmdWriteAccelerationStructuresPropertiesNV";
  const ProtectScope protect(data->reporter->protects());
  if (ctx.Enabled(kCheckCopies) && ValidateWritePropertiesNV(ctx, commandBuffer, accelerationStructureCount,
                                                             pAccelerationStructures, queryType, queryPool)) {
    return WithholdRecordedCommand(*data, function, commandBuffer, protect);
  }
  data->dispatch.CmdWriteAccelerationStructuresPropertiesNV(commandBuffer, accelerationStructureCount,
                                                            pAccelerationStructures, queryType, queryPool, firstQuery);
  RecordCmdWritePropertiesNV(data->state, commandBuffer, accelerationStructureCount, pAccelerationStructures, queryType,
                             queryPool, firstQuery);
}

}  // namespace asval::hooks
