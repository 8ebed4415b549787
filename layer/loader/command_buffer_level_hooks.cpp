// Command pools and command buffers: which pool each command buffer came from, its level, and whether it is
// protected (DeviceState::command_buffer_levels). The build commands' commandBuffer-09547 needs the last.
//
// Other per-command-buffer state (operation logs for the build history) may hook these same commands: add
// to these functions rather than defining a second hook.
#include "history_record.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateCommandPool(VkDevice device, const VkCommandPoolCreateInfo* pCreateInfo,
                                                 const VkAllocationCallbacks* pAllocator, VkCommandPool* pCommandPool) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateCommandPool(device, pCreateInfo, pAllocator, pCommandPool);
  if (result == VK_SUCCESS) {
    CommandBufferLevels& levels = data->state.command_buffer_levels;
    levels.pools.insert_or_assign(*pCommandPool, pCreateInfo->flags);
    if (pCreateInfo->flags & VK_COMMAND_POOL_CREATE_PROTECTED_BIT) {
      levels.any_protected_pool.store(true, std::memory_order_release);
    }
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyCommandPool(VkDevice device, VkCommandPool commandPool,
                                              const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  if (commandPool) {
    // Forget the pool's command buffers before the driver frees them: once it has, their handles may be
    // handed out again by another thread's allocation, whose records must not be erased here.
    CommandBufferLevels& levels = data->state.command_buffer_levels;
    levels.pools.erase(commandPool);
    const auto owned = levels.buffers.snapshot(
        [commandPool](VkCommandBuffer, const CommandBufferInfo& info) { return info.pool == commandPool; });
    for (const auto& entry : owned) levels.buffers.erase(entry.first);
    data->state.history.command_buffers.DestroyPool(commandPool);  // and their operation logs
  }
  data->dispatch.DestroyCommandPool(device, commandPool, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL AllocateCommandBuffers(VkDevice device, const VkCommandBufferAllocateInfo* pAllocateInfo,
                                                      VkCommandBuffer* pCommandBuffers) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.AllocateCommandBuffers(device, pAllocateInfo, pCommandBuffers);
  if (result == VK_SUCCESS) {
    CommandBufferLevels& levels = data->state.command_buffer_levels;
    const std::optional<VkCommandPoolCreateFlags> pool_flags = levels.pools.find(pAllocateInfo->commandPool);
    CommandBufferInfo info;
    info.pool = pAllocateInfo->commandPool;
    info.level = pAllocateInfo->level;
    info.is_protected = pool_flags && (*pool_flags & VK_COMMAND_POOL_CREATE_PROTECTED_BIT);
    // insert_or_assign: a recycled handle replaces whatever an earlier command buffer left.
    for (uint32_t i = 0; i < pAllocateInfo->commandBufferCount; ++i) {
      levels.buffers.insert_or_assign(pCommandBuffers[i], info);
    }
    // Empty operation logs for the build history.
    data->state.history.command_buffers.Allocate(pAllocateInfo->commandPool, pAllocateInfo->commandBufferCount,
                                                 pCommandBuffers);
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL FreeCommandBuffers(VkDevice device, VkCommandPool commandPool, uint32_t commandBufferCount,
                                              const VkCommandBuffer* pCommandBuffers) {
  DeviceData* data = GetDeviceData(device);
  // Before the downcall, for the same reason as in DestroyCommandPool.
  for (uint32_t i = 0; i < commandBufferCount; ++i) {
    if (pCommandBuffers[i]) data->state.command_buffer_levels.buffers.erase(pCommandBuffers[i]);
  }
  data->state.history.command_buffers.Free(commandBufferCount, pCommandBuffers);
  data->dispatch.FreeCommandBuffers(device, commandPool, commandBufferCount, pCommandBuffers);
}

}  // namespace asval::hooks
