// Copies, serialization and property queries of acceleration structures: the copies family's record-time
// rules, then (after a successful downcall) the operation for the build history: logged into the command
// buffer (device commands, applied at submission) or checked now and applied on completion (host commands).
#include "copies.h"
#include "history_host.h"
#include "host_copy_rules.h"
#include "host_command_features.h"
#include "history_recorder.h"
#include "layer_data.h"
#include "vk_intercepts.h"
#include "withhold.h"

namespace asval::hooks {

namespace {

// A host copy: its feature, record-time rules (copies family, then the host family's), history rules, the downcall,
// and its operations applied (or deferred).
template <typename MakeOps, typename Validate, typename ValidateHost, typename Downcall>
VkResult HostCopy(DeviceData& data, const char* function, const char* feature_vuid, VkDeferredOperationKHR deferred,
                  MakeOps&& make_ops, Validate&& validate, ValidateHost&& validate_host, Downcall&& downcall) {
  const CheckContext ctx = MakeCheckContext(data);
  const ProtectScope protect(data.reporter->protects());
  bool skip = ctx.Enabled(kCheckFeatures) && ValidateHostCommandFeature(ctx, function, feature_vuid);
  skip |= ctx.Enabled(kCheckCopies) && validate(ctx);
  if (ctx.Enabled(kCheckHost)) {
    skip |= ValidateHostCopyDeferred(ctx, function, deferred);
    skip |= validate_host(ctx);
  }
  OpBatch batch;
  if (data.state.history_tracked) batch = make_ops();
  skip |= ValidateHostOps(ctx, batch, function);
  // Skipped by the app's callback, or withheld by protect mode: the copy did not happen.
  if (skip) return WithholdHostCommand(data, function, data.device, protect);
  const VkResult result = downcall();
  FinishHostOps(data.state, std::move(batch), deferred, result);
  return result;
}

// The capture of a device serialization's bytes (layer/capture): its index in the recording's capture log plus
// one, or 0 (capture off, history not tracked, a command buffer the layer does not know, a null address).
uint32_t CaptureBlob(DeviceData& data, VkCommandBuffer cb, VkDeviceAddress address, VkAccelerationStructureKHR src) {
  if (!data.capture_tracker || !data.state.history_tracked || address == 0) return 0;
  const std::shared_ptr<CommandBufferState> recording = data.state.command_buffers.Find(cb);
  if (!recording) return 0;  // a command buffer the layer never saw: its submission makes history unknown
  return CaptureSerializedBlob(MakeCaptureContext(data), cb, *recording, address, src);
}

}  // namespace

VKAPI_ATTR void VKAPI_CALL CmdCopyAccelerationStructureKHR(VkCommandBuffer commandBuffer,
                                                           const VkCopyAccelerationStructureInfoKHR* pInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx = MakeCheckContext(*data);
  const ProtectScope protect(data->reporter->protects());
  if (pInfo && ctx.Enabled(kCheckCopies) &&
      ValidateCopyInfo(ctx, "vkCmdCopyAccelerationStructureKHR", commandBuffer, *pInfo)) {
    return WithholdRecordedCommand(*data, "vkCmdCopyAccelerationStructureKHR", commandBuffer, protect);
  }
  data->dispatch.CmdCopyAccelerationStructureKHR(commandBuffer, pInfo);
  if (pInfo) RecordCmdCopy(data->state, commandBuffer, *pInfo);
}

VKAPI_ATTR void VKAPI_CALL CmdCopyAccelerationStructureToMemoryKHR(
    VkCommandBuffer commandBuffer, const VkCopyAccelerationStructureToMemoryInfoKHR* pInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx = MakeCheckContext(*data);
  const ProtectScope protect(data->reporter->protects());
  if (pInfo && ctx.Enabled(kCheckCopies) &&
      ValidateCopyToMemoryInfo(ctx, "vkCmdCopyAccelerationStructureToMemoryKHR", commandBuffer, *pInfo)) {
    return WithholdRecordedCommand(*data, "vkCmdCopyAccelerationStructureToMemoryKHR", commandBuffer, protect);
  }
  data->dispatch.CmdCopyAccelerationStructureToMemoryKHR(commandBuffer, pInfo);
  // Post-record of the capture: the bytes just serialized, copied once the serialization executed (layer/capture),
  // so that a deserialization of them can be verified by content.
  const uint32_t captured = pInfo ? CaptureBlob(*data, commandBuffer, pInfo->dst.deviceAddress, pInfo->src) : 0;
  if (pInfo) RecordCmdCopyToMemory(data->state, commandBuffer, *pInfo, captured);
}

VKAPI_ATTR void VKAPI_CALL CmdCopyMemoryToAccelerationStructureKHR(
    VkCommandBuffer commandBuffer, const VkCopyMemoryToAccelerationStructureInfoKHR* pInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx = MakeCheckContext(*data);
  const ProtectScope protect(data->reporter->protects());
  if (pInfo && ctx.Enabled(kCheckCopies) &&
      ValidateCopyMemoryToInfo(ctx, "vkCmdCopyMemoryToAccelerationStructureKHR", commandBuffer, *pInfo)) {
    return WithholdRecordedCommand(*data, "vkCmdCopyMemoryToAccelerationStructureKHR", commandBuffer, protect);
  }
  // Pre-record of the capture: the bytes the deserialization will read, copied just before it executes.
  const uint32_t captured = pInfo ? CaptureBlob(*data, commandBuffer, pInfo->src.deviceAddress, VK_NULL_HANDLE) : 0;
  data->dispatch.CmdCopyMemoryToAccelerationStructureKHR(commandBuffer, pInfo);
  if (pInfo) RecordCmdCopyMemoryTo(data->state, commandBuffer, *pInfo, captured);
}

VKAPI_ATTR void VKAPI_CALL CmdWriteAccelerationStructuresPropertiesKHR(
    VkCommandBuffer commandBuffer, uint32_t accelerationStructureCount,
    const VkAccelerationStructureKHR* pAccelerationStructures, VkQueryType queryType, VkQueryPool queryPool,
    uint32_t firstQuery) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx = MakeCheckContext(*data);
  const char* function = "vkCmdWriteAccelerationStructuresPropertiesKHR";
  const ProtectScope protect(data->reporter->protects());
  if (ctx.Enabled(kCheckCopies) &&
      ValidateWriteProperties(ctx, function, commandBuffer, accelerationStructureCount, pAccelerationStructures,
                              queryType, queryPool, firstQuery)) {
    return WithholdRecordedCommand(*data, function, commandBuffer, protect);
  }
  data->dispatch.CmdWriteAccelerationStructuresPropertiesKHR(commandBuffer, accelerationStructureCount,
                                                             pAccelerationStructures, queryType, queryPool, firstQuery);
  RecordCmdWriteProperties(data->state, commandBuffer, accelerationStructureCount, pAccelerationStructures, queryType,
                           queryPool, firstQuery);
}

VKAPI_ATTR VkResult VKAPI_CALL CopyAccelerationStructureKHR(VkDevice device, VkDeferredOperationKHR deferredOperation,
                                                            const VkCopyAccelerationStructureInfoKHR* pInfo) {
  DeviceData* data = GetDeviceData(device);
  const char* function = "vkCopyAccelerationStructureKHR";
  if (!pInfo) return data->dispatch.CopyAccelerationStructureKHR(device, deferredOperation, pInfo);
  return HostCopy(
      *data, function, "accelerationStructureHostCommands-03582", deferredOperation,
      [&] { return HostCopyOps(*pInfo); },
      [&](const CheckContext& ctx) { return ValidateCopyInfo(ctx, function, VK_NULL_HANDLE, *pInfo); },
      [&](const CheckContext& ctx) { return ValidateHostCopyStructures(ctx, *pInfo); },
      [&] { return data->dispatch.CopyAccelerationStructureKHR(device, deferredOperation, pInfo); });
}

VKAPI_ATTR VkResult VKAPI_CALL CopyAccelerationStructureToMemoryKHR(
    VkDevice device, VkDeferredOperationKHR deferredOperation,
    const VkCopyAccelerationStructureToMemoryInfoKHR* pInfo) {
  DeviceData* data = GetDeviceData(device);
  const char* function = "vkCopyAccelerationStructureToMemoryKHR";
  if (!pInfo) return data->dispatch.CopyAccelerationStructureToMemoryKHR(device, deferredOperation, pInfo);
  return HostCopy(
      *data, function, "accelerationStructureHostCommands-03584", deferredOperation,
      [&] { return HostCopyToMemoryOps(*pInfo); },
      [&](const CheckContext& ctx) { return ValidateCopyToMemoryInfo(ctx, function, VK_NULL_HANDLE, *pInfo); },
      [&](const CheckContext& ctx) { return ValidateHostCopyToMemory(ctx, *pInfo); },
      [&] { return data->dispatch.CopyAccelerationStructureToMemoryKHR(device, deferredOperation, pInfo); });
}

VKAPI_ATTR VkResult VKAPI_CALL CopyMemoryToAccelerationStructureKHR(
    VkDevice device, VkDeferredOperationKHR deferredOperation,
    const VkCopyMemoryToAccelerationStructureInfoKHR* pInfo) {
  DeviceData* data = GetDeviceData(device);
  const char* function = "vkCopyMemoryToAccelerationStructureKHR";
  if (!pInfo) return data->dispatch.CopyMemoryToAccelerationStructureKHR(device, deferredOperation, pInfo);
  return HostCopy(
      *data, function, "accelerationStructureHostCommands-03583", deferredOperation,
      [&] { return HostCopyMemoryToOps(*pInfo); },
      [&](const CheckContext& ctx) { return ValidateCopyMemoryToInfo(ctx, function, VK_NULL_HANDLE, *pInfo); },
      [&](const CheckContext& ctx) { return ValidateHostCopyMemoryTo(ctx, *pInfo); },
      [&] { return data->dispatch.CopyMemoryToAccelerationStructureKHR(device, deferredOperation, pInfo); });
}

VKAPI_ATTR VkResult VKAPI_CALL WriteAccelerationStructuresPropertiesKHR(
    VkDevice device, uint32_t accelerationStructureCount, const VkAccelerationStructureKHR* pAccelerationStructures,
    VkQueryType queryType, size_t dataSize, void* pData, size_t stride) {
  DeviceData* data = GetDeviceData(device);
  const char* function = "vkWriteAccelerationStructuresPropertiesKHR";
  const CheckContext ctx = MakeCheckContext(*data);
  const ProtectScope protect(data->reporter->protects());
  bool skip = ctx.Enabled(kCheckFeatures) &&
              ValidateHostCommandFeature(ctx, function, "accelerationStructureHostCommands-03585");
  if (ctx.Enabled(kCheckCopies)) {
    skip |= ValidateWriteProperties(ctx, function, VK_NULL_HANDLE, accelerationStructureCount, pAccelerationStructures,
                                    queryType, VK_NULL_HANDLE, 0);
    skip |= ValidateHostPropertyData(ctx, function, accelerationStructureCount, queryType, dataSize, pData, stride);
  }
  if (ctx.Enabled(kCheckHost)) {
    skip |= ValidateHostPropertyStructures(ctx, accelerationStructureCount, pAccelerationStructures);
  }
  if (data->state.history_tracked) {
    skip |= ValidateHostOps(ctx, HostWritePropertiesOps(accelerationStructureCount, pAccelerationStructures, queryType),
                            function);
  }
  if (skip) return WithholdHostCommand(*data, function, device, protect);
  const VkResult result = data->dispatch.WriteAccelerationStructuresPropertiesKHR(
      device, accelerationStructureCount, pAccelerationStructures, queryType, dataSize, pData, stride);
  if (result == VK_SUCCESS && queryType == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR) {
    RecordHostSerializationSizes(data->state, accelerationStructureCount, pAccelerationStructures, pData, stride);
  }
  return result;
}

}  // namespace asval::hooks
