// Deferred host operations: a host build or copy that returned VK_OPERATION_DEFERRED_KHR changes the
// structures' histories only once the layer sees it complete successfully: vkDeferredOperationJoinKHR or
// vkGetDeferredOperationResultKHR reporting completion, or, at the latest, vkDestroyDeferredOperationKHR
// (the app may destroy a completed operation without asking for its result).
#include "history_recorder.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

namespace {

// The operation's own result once it is complete (asked of the driver: a query without side effects).
// `last`: the operation is being destroyed, so whatever is still pending is dropped.
void CompleteIfDone(DeviceData& data, VkDevice device, VkDeferredOperationKHR operation, bool last) {
  if (!HasDeferredOps(data.state, operation)) return;
  const VkResult result = data.dispatch.GetDeferredOperationResultKHR
                              ? data.dispatch.GetDeferredOperationResultKHR(device, operation)
                              : VK_NOT_READY;
  if (result != VK_NOT_READY || last) CompleteDeferredOps(data.state, operation, result);
}

}  // namespace

VKAPI_ATTR VkResult VKAPI_CALL DeferredOperationJoinKHR(VkDevice device, VkDeferredOperationKHR operation) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.DeferredOperationJoinKHR(device, operation);
  // VK_SUCCESS: the operation is complete (its own result may still be an error).
  if (result == VK_SUCCESS) CompleteIfDone(*data, device, operation, false);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL GetDeferredOperationResultKHR(VkDevice device, VkDeferredOperationKHR operation) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.GetDeferredOperationResultKHR(device, operation);
  if (result != VK_NOT_READY) CompleteDeferredOps(data->state, operation, result);
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyDeferredOperationKHR(VkDevice device, VkDeferredOperationKHR operation,
                                                       const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  if (operation) CompleteIfDone(*data, device, operation, true);
  data->dispatch.DestroyDeferredOperationKHR(device, operation, pAllocator);
}

}  // namespace asval::hooks
