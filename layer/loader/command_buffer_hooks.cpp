// Command pools and command buffers: which pool each command buffer came from, its level, whether it is
// protected (commandBuffer-09547), and the acceleration-structure operations each recording holds
// (CommandBufferMap, layer/state/command_buffers.h).
#include "capture_saves.h"
#include "history_recorder.h"
#include "layer_data.h"
#include "ray_recorder.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateCommandPool(VkDevice device, const VkCommandPoolCreateInfo* pCreateInfo,
                                                 const VkAllocationCallbacks* pAllocator, VkCommandPool* pCommandPool) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateCommandPool(device, pCreateInfo, pAllocator, pCommandPool);
  if (result == VK_SUCCESS) data->state.command_buffers.CreatePool(*pCommandPool, pCreateInfo->flags);
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyCommandPool(VkDevice device, VkCommandPool commandPool,
                                              const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  // Before the downcall: see CommandBufferMap::DestroyPool.
  if (commandPool) {
    data->state.command_buffers.DestroyPool(commandPool, [&](VkCommandBuffer cb) {
      data->reporter->ForgetObjectName(Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, cb));
    });
  }
  data->dispatch.DestroyCommandPool(device, commandPool, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL ResetCommandPool(VkDevice device, VkCommandPool commandPool,
                                                VkCommandPoolResetFlags flags) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.ResetCommandPool(device, commandPool, flags);
  if (result == VK_SUCCESS) data->state.command_buffers.ResetPool(commandPool);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL AllocateCommandBuffers(VkDevice device, const VkCommandBufferAllocateInfo* pAllocateInfo,
                                                      VkCommandBuffer* pCommandBuffers) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.AllocateCommandBuffers(device, pAllocateInfo, pCommandBuffers);
  if (result == VK_SUCCESS) data->state.command_buffers.Allocate(*pAllocateInfo, pCommandBuffers);
  return result;
}

VKAPI_ATTR void VKAPI_CALL FreeCommandBuffers(VkDevice device, VkCommandPool commandPool, uint32_t commandBufferCount,
                                              const VkCommandBuffer* pCommandBuffers) {
  DeviceData* data = GetDeviceData(device);
  // Before the downcall, for the same reason as in DestroyCommandPool.
  data->state.command_buffers.Free(commandBufferCount, pCommandBuffers);
  for (uint32_t i = 0; pCommandBuffers && i < commandBufferCount; ++i) {
    if (pCommandBuffers[i]) data->reporter->ForgetObjectName(Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, pCommandBuffers[i]));
  }
  data->dispatch.FreeCommandBuffers(device, commandPool, commandBufferCount, pCommandBuffers);
}

VKAPI_ATTR VkResult VKAPI_CALL BeginCommandBuffer(VkCommandBuffer commandBuffer,
                                                  const VkCommandBufferBeginInfo* pBeginInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const VkResult result = data->dispatch.BeginCommandBuffer(commandBuffer, pBeginInfo);
  // vkBeginCommandBuffer resets a recorded command buffer implicitly.
  if (result == VK_SUCCESS) {
    // No begin info (invalid): taken as SIMULTANEOUS_USE, the case that uses no event (capture_run_end.h).
    const VkCommandBufferUsageFlags usage =
        pBeginInfo ? pBeginInfo->flags : VkCommandBufferUsageFlags{VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT};
    data->state.command_buffers.Begin(commandBuffer, usage);
  }
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL EndCommandBuffer(VkCommandBuffer commandBuffer) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);  // the run's captures are the recording's last commands
  const VkResult result = data->dispatch.EndCommandBuffer(commandBuffer);
  if (result == VK_SUCCESS) data->state.command_buffers.End(commandBuffer);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL ResetCommandBuffer(VkCommandBuffer commandBuffer, VkCommandBufferResetFlags flags) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const VkResult result = data->dispatch.ResetCommandBuffer(commandBuffer, flags);
  if (result == VK_SUCCESS) data->state.command_buffers.Reset(commandBuffer);
  return result;
}

VKAPI_ATTR void VKAPI_CALL CmdExecuteCommands(VkCommandBuffer commandBuffer, uint32_t commandBufferCount,
                                              const VkCommandBuffer* pCommandBuffers) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);  // the secondaries may hold barriers
  if (!data->capture_pool || !pCommandBuffers) {
    data->dispatch.CmdExecuteCommands(commandBuffer, commandBufferCount, pCommandBuffers);
    RecordExecuteCommands(data->state, commandBuffer, commandBufferCount, pCommandBuffers);
  } else {
    // Bends the order: a secondary whose captures this recording already reads (executed twice) has what the
    // executions before it wrote saved first, so the app's array goes down in parts, around the layer's copies, as
    // the recorder finds them (capture_saves.h); the rest goes down after.
    ExecuteCommandsSaver saver(data->dispatch, commandBuffer, pCommandBuffers);
    RecordExecuteCommands(data->state, commandBuffer, commandBufferCount, pCommandBuffers, &saver);
    saver.PassDown(commandBufferCount);
  }
  // Protect mode: a secondary holding a withheld command marks the primary (a single load until one is marked).
  data->state.command_buffers.InheritWithheld(commandBuffer, commandBufferCount, pCommandBuffers);
  RecordExecuteForTraces(data->state, commandBuffer);  // the primary's bindings are undefined now
}

VKAPI_ATTR void VKAPI_CALL CmdBindPipeline(VkCommandBuffer commandBuffer, VkPipelineBindPoint pipelineBindPoint,
                                           VkPipeline pipeline) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdBindPipeline(commandBuffer, pipelineBindPoint, pipeline);
  // Only where the layer's dispatch may replace it (capture_reducer.h): elsewhere a pass-through.
  if (pipelineBindPoint == VK_PIPELINE_BIND_POINT_COMPUTE && data->capture_pool && data->capture_pool->dispatches()) {
    RecordBindComputePipeline(data->state, commandBuffer, pipeline);
  }
  RecordBindPipelineForTraces(data->state, commandBuffer, pipelineBindPoint, pipeline);
}

}  // namespace asval::hooks
