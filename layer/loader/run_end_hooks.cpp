// The commands that end a run of build commands (layer/state/capture_run.h): the captures the run's builds planned
// are recorded first (capture_run_end.h), then the app's command goes down unchanged. These are the commands that
// can order a later write of a build's inputs after the build's reads: barriers, event waits (and the event
// signals another queue may wait for), render pass instances with their dependencies. vkEndCommandBuffer and
// vkCmdExecuteCommands end a run too (command_buffer_hooks.cpp). While no command buffer of the device holds an
// open run, each costs one load.
#include "capture_run_end.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR void VKAPI_CALL CmdPipelineBarrier(VkCommandBuffer commandBuffer, VkPipelineStageFlags srcStageMask,
                                              VkPipelineStageFlags dstStageMask, VkDependencyFlags dependencyFlags,
                                              uint32_t memoryBarrierCount, const VkMemoryBarrier* pMemoryBarriers,
                                              uint32_t bufferMemoryBarrierCount,
                                              const VkBufferMemoryBarrier* pBufferMemoryBarriers,
                                              uint32_t imageMemoryBarrierCount,
                                              const VkImageMemoryBarrier* pImageMemoryBarriers) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdPipelineBarrier(commandBuffer, srcStageMask, dstStageMask, dependencyFlags, memoryBarrierCount,
                                    pMemoryBarriers, bufferMemoryBarrierCount, pBufferMemoryBarriers,
                                    imageMemoryBarrierCount, pImageMemoryBarriers);
}

VKAPI_ATTR void VKAPI_CALL CmdPipelineBarrier2(VkCommandBuffer commandBuffer, const VkDependencyInfo* pDependencyInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdPipelineBarrier2(commandBuffer, pDependencyInfo);
}

VKAPI_ATTR void VKAPI_CALL CmdWaitEvents(VkCommandBuffer commandBuffer, uint32_t eventCount, const VkEvent* pEvents,
                                         VkPipelineStageFlags srcStageMask, VkPipelineStageFlags dstStageMask,
                                         uint32_t memoryBarrierCount, const VkMemoryBarrier* pMemoryBarriers,
                                         uint32_t bufferMemoryBarrierCount,
                                         const VkBufferMemoryBarrier* pBufferMemoryBarriers,
                                         uint32_t imageMemoryBarrierCount,
                                         const VkImageMemoryBarrier* pImageMemoryBarriers) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdWaitEvents(commandBuffer, eventCount, pEvents, srcStageMask, dstStageMask, memoryBarrierCount,
                               pMemoryBarriers, bufferMemoryBarrierCount, pBufferMemoryBarriers,
                               imageMemoryBarrierCount, pImageMemoryBarriers);
}

VKAPI_ATTR void VKAPI_CALL CmdWaitEvents2(VkCommandBuffer commandBuffer, uint32_t eventCount, const VkEvent* pEvents,
                                          const VkDependencyInfo* pDependencyInfos) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdWaitEvents2(commandBuffer, eventCount, pEvents, pDependencyInfos);
}

VKAPI_ATTR void VKAPI_CALL CmdSetEvent(VkCommandBuffer commandBuffer, VkEvent event, VkPipelineStageFlags stageMask) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdSetEvent(commandBuffer, event, stageMask);
}

VKAPI_ATTR void VKAPI_CALL CmdSetEvent2(VkCommandBuffer commandBuffer, VkEvent event,
                                        const VkDependencyInfo* pDependencyInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdSetEvent2(commandBuffer, event, pDependencyInfo);
}

VKAPI_ATTR void VKAPI_CALL CmdResetEvent(VkCommandBuffer commandBuffer, VkEvent event, VkPipelineStageFlags stageMask) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdResetEvent(commandBuffer, event, stageMask);
}

VKAPI_ATTR void VKAPI_CALL CmdResetEvent2(VkCommandBuffer commandBuffer, VkEvent event,
                                          VkPipelineStageFlags2 stageMask) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdResetEvent2(commandBuffer, event, stageMask);
}

VKAPI_ATTR void VKAPI_CALL CmdBeginRenderPass(VkCommandBuffer commandBuffer, const VkRenderPassBeginInfo* pRenderPassBegin,
                                              VkSubpassContents contents) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdBeginRenderPass(commandBuffer, pRenderPassBegin, contents);
}

VKAPI_ATTR void VKAPI_CALL CmdBeginRenderPass2(VkCommandBuffer commandBuffer,
                                               const VkRenderPassBeginInfo* pRenderPassBegin,
                                               const VkSubpassBeginInfo* pSubpassBeginInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdBeginRenderPass2(commandBuffer, pRenderPassBegin, pSubpassBeginInfo);
}

VKAPI_ATTR void VKAPI_CALL CmdBeginRendering(VkCommandBuffer commandBuffer, const VkRenderingInfo* pRenderingInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  EndCaptureRun(*data, commandBuffer);
  data->dispatch.CmdBeginRendering(commandBuffer, pRenderingInfo);
}

}  // namespace asval::hooks
