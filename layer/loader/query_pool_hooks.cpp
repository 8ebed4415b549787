// Query pools: their type and size for the property-query rules (queryPool-02493, query-04880), and the
// serialization sizes the app reads back, which the history attaches to the structures queried
// (VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561).
#include "history_record.h"
#include "history_submit.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateQueryPool(VkDevice device, const VkQueryPoolCreateInfo* pCreateInfo,
                                               const VkAllocationCallbacks* pAllocator, VkQueryPool* pQueryPool) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateQueryPool(device, pCreateInfo, pAllocator, pQueryPool);
  if (result == VK_SUCCESS) {
    data->state.history.query_pools.insert_or_assign(*pQueryPool,
                                                     QueryPoolState{pCreateInfo->queryType, pCreateInfo->queryCount});
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyQueryPool(VkDevice device, VkQueryPool queryPool,
                                            const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  if (queryPool) {
    // Before the downcall: afterwards the handle value may be handed out again by another thread.
    std::optional<QueryPoolState> pool = data->state.history.query_pools.pop(queryPool);
    if (pool && pool->type == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR) {
      std::unique_lock<std::mutex> lock = data->state.history.store.Lock();
      data->state.history.store.ForgetPool(queryPool);
    }
  }
  data->dispatch.DestroyQueryPool(device, queryPool, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL GetQueryPoolResults(VkDevice device, VkQueryPool queryPool, uint32_t firstQuery,
                                                   uint32_t queryCount, size_t dataSize, void* pData,
                                                   VkDeviceSize stride, VkQueryResultFlags flags) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result =
      data->dispatch.GetQueryPoolResults(device, queryPool, firstQuery, queryCount, dataSize, pData, stride, flags);
  // Only serialization sizes interest the layer: other pools (timestamps, occlusion) cost one map lookup.
  if (HistoryTracked(data->instance->settings.enabled_checks)) {
    std::optional<QueryPoolState> pool = data->state.history.query_pools.find(queryPool);
    if (pool && pool->type == VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR) {
      RecordQueryResults(data->state, queryPool, firstQuery, queryCount, dataSize, pData, stride, flags, result);
    }
  }
  return result;
}

}  // namespace asval::hooks
