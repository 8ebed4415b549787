// Query pools: their type and size for the property-query rules (queryPool-02493, query-04880), and the
// serialization sizes the app reads back, which the history attaches to the structures queried
// (VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561).
#include "history_recorder.h"
#include "layer_data.h"
#include "state_tracker.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateQueryPool(VkDevice device, const VkQueryPoolCreateInfo* pCreateInfo,
                                               const VkAllocationCallbacks* pAllocator, VkQueryPool* pQueryPool) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateQueryPool(device, pCreateInfo, pAllocator, pQueryPool);
  if (result == VK_SUCCESS) RecordCreateQueryPool(data->state, *pCreateInfo, *pQueryPool);
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyQueryPool(VkDevice device, VkQueryPool queryPool,
                                            const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  // Before the downcall: afterwards the handle value may be handed out again by another thread.
  if (queryPool) RecordDestroyQueryPool(data->state, queryPool);
  data->dispatch.DestroyQueryPool(device, queryPool, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL GetQueryPoolResults(VkDevice device, VkQueryPool queryPool, uint32_t firstQuery,
                                                   uint32_t queryCount, size_t dataSize, void* pData,
                                                   VkDeviceSize stride, VkQueryResultFlags flags) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result =
      data->dispatch.GetQueryPoolResults(device, queryPool, firstQuery, queryCount, dataSize, pData, stride, flags);
  RecordQueryResults(data->state, queryPool, firstQuery, queryCount, dataSize, pData, stride, flags, result);
  // Results the device wrote: the host may learn from them that work in flight ran this far (in_flight.h).
  if (result == VK_SUCCESS && data->in_flight) data->in_flight->HostReadDeviceProgress();
  return result;
}

}  // namespace asval::hooks
