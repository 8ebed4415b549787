// Semaphores, for the execution order across queues (layer/state/submission_order.h): which semaphores are
// timeline semaphores and their initial values, which are shared outside the layer's view (created exportable, or
// imported), and the values the host signals, which may let deferred batches run (ordered_batches.h).
#include <mutex>
#include <new>

#include "layer_data.h"
#include "ordered_batches.h"
#include "vk_intercepts.h"
#include "vk_struct_chain.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateSemaphore(VkDevice device, const VkSemaphoreCreateInfo* pCreateInfo,
                                               const VkAllocationCallbacks* pAllocator, VkSemaphore* pSemaphore) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.CreateSemaphore(device, pCreateInfo, pAllocator, pSemaphore);
  if (result != VK_SUCCESS || !data->state.history_tracked) return result;
  const auto* type =
      FindInChain<VkSemaphoreTypeCreateInfo>(pCreateInfo->pNext, VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO);
  if (!type || type->semaphoreType != VK_SEMAPHORE_TYPE_TIMELINE) return result;
  const bool exportable =
      FindInChain<VkExportSemaphoreCreateInfo>(pCreateInfo->pNext, VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO);
  std::lock_guard<std::recursive_mutex> lock(data->state.history.submission_order);
  try {
    data->state.history.order.TimelineCreated(*pSemaphore, type->initialValue, exportable);
  } catch (const std::bad_alloc&) {
    // Not known as a timeline semaphore: its waits are applied in host order, as before the layer ordered them.
    data->state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
  }
  return result;
}

// Before the downcall: the driver may hand the handle value to another thread's new semaphore.
VKAPI_ATTR void VKAPI_CALL DestroySemaphore(VkDevice device, VkSemaphore semaphore,
                                            const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  const SubmissionOrder& order = data->state.history.order;
  if (semaphore && data->state.history_tracked && (order.any_timeline() || order.backlog() != 0)) {
    std::lock_guard<std::recursive_mutex> lock(data->state.history.submission_order);
    data->state.history.order.SemaphoreDestroyed(semaphore);
  }
  // The batches that signal it completed (it may be destroyed only then); the handle no longer names them.
  if (semaphore && data->in_flight) data->in_flight->SemaphoreDestroyed(semaphore);
  data->dispatch.DestroySemaphore(device, semaphore, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL ImportSemaphoreFdKHR(VkDevice device, const VkImportSemaphoreFdInfoKHR* pInfo) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.ImportSemaphoreFdKHR(device, pInfo);
  if (result == VK_SUCCESS && data->state.history_tracked && data->state.history.order.any_timeline()) {
    std::lock_guard<std::recursive_mutex> lock(data->state.history.submission_order);
    data->state.history.order.SemaphoreImported(pInfo->semaphore);
  }
  return result;
}

// Also vkSignalSemaphoreKHR. The lock is held across the downcall: no submission is placed between the signal and
// the deferred batches it lets run.
VKAPI_ATTR VkResult VKAPI_CALL SignalSemaphore(VkDevice device, const VkSemaphoreSignalInfo* pSignalInfo) {
  DeviceData* data = GetDeviceData(device);
  SubmissionOrder& order = data->state.history.order;
  if (!data->state.history_tracked || !order.any_timeline()) return data->dispatch.SignalSemaphore(device, pSignalInfo);
  std::lock_guard<std::recursive_mutex> lock(data->state.history.submission_order);
  const VkResult result = data->dispatch.SignalSemaphore(device, pSignalInfo);
  if (result == VK_SUCCESS) {
    order.Signaled(pSignalInfo->semaphore, pSignalInfo->value);
    ApplyReadyBatches(*data);
  }
  return result;
}

}  // namespace asval::hooks
