// Command-buffer lifetime for the build history: beginning or resetting a command buffer empties its
// operation log, and vkCmdExecuteCommands copies the secondaries' operations into the primary's log.
// (Allocation, freeing and pool destruction are hooked in command_buffer_level_hooks.cpp, which fills both the
// level records and the operation logs.)
#include "history_record.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL BeginCommandBuffer(VkCommandBuffer commandBuffer,
                                                  const VkCommandBufferBeginInfo* pBeginInfo) {
  DeviceData* data = GetDeviceData(commandBuffer);
  // vkBeginCommandBuffer resets a recorded command buffer implicitly.
  ResetCommandBufferLog(data->state, commandBuffer);
  return data->dispatch.BeginCommandBuffer(commandBuffer, pBeginInfo);
}

VKAPI_ATTR VkResult VKAPI_CALL ResetCommandBuffer(VkCommandBuffer commandBuffer, VkCommandBufferResetFlags flags) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const VkResult result = data->dispatch.ResetCommandBuffer(commandBuffer, flags);
  if (result == VK_SUCCESS) ResetCommandBufferLog(data->state, commandBuffer);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL ResetCommandPool(VkDevice device, VkCommandPool commandPool,
                                                VkCommandPoolResetFlags flags) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.ResetCommandPool(device, commandPool, flags);
  if (result == VK_SUCCESS) data->state.history.command_buffers.ResetPool(commandPool);
  return result;
}

VKAPI_ATTR void VKAPI_CALL CmdExecuteCommands(VkCommandBuffer commandBuffer, uint32_t commandBufferCount,
                                              const VkCommandBuffer* pCommandBuffers) {
  DeviceData* data = GetDeviceData(commandBuffer);
  data->dispatch.CmdExecuteCommands(commandBuffer, commandBufferCount, pCommandBuffers);
  RecordExecuteCommands(data->state, data->instance->settings.enabled_checks, commandBuffer, commandBufferCount,
                        pCommandBuffers);
}

}  // namespace asval::hooks
