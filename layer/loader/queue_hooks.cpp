// Submissions: the operations of each submitted command buffer are checked against the structures' build
// history and applied to it, in submission order (history_submit.h). A finding whose callback returns VK_TRUE
// keeps the whole submission from the driver, as the Khronos layer does, and its history changes are undone;
// so are those of a submission the driver rejects.
#include "history_submit.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue queue, uint32_t submitCount, const VkSubmitInfo* pSubmits,
                                           VkFence fence) {
  DeviceData* data = GetDeviceData(queue);
  SubmitHistory history(data->state, *data->reporter, data->instance->settings.enabled_checks);
  const Location root("vkQueueSubmit");
  for (uint32_t i = 0; i < submitCount; ++i) {
    for (uint32_t j = 0; j < pSubmits[i].commandBufferCount; ++j) {
      history.Apply(pSubmits[i].pCommandBuffers[j], root.Field("pSubmits", i).Field("pCommandBuffers", j));
    }
  }
  if (history.Finish()) return VK_ERROR_VALIDATION_FAILED_EXT;
  const VkResult result = data->dispatch.QueueSubmit(queue, submitCount, pSubmits, fence);
  if (result != VK_SUCCESS) history.Undo();
  return result;
}

// Also vkQueueSubmit2KHR (the generated intercept table maps the alias here).
VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue queue, uint32_t submitCount, const VkSubmitInfo2* pSubmits,
                                            VkFence fence) {
  DeviceData* data = GetDeviceData(queue);
  SubmitHistory history(data->state, *data->reporter, data->instance->settings.enabled_checks);
  const Location root("vkQueueSubmit2");
  for (uint32_t i = 0; i < submitCount; ++i) {
    for (uint32_t j = 0; j < pSubmits[i].commandBufferInfoCount; ++j) {
      history.Apply(pSubmits[i].pCommandBufferInfos[j].commandBuffer,
                    root.Field("pSubmits", i).Field("pCommandBufferInfos", j).Field("commandBuffer"));
    }
  }
  if (history.Finish()) return VK_ERROR_VALIDATION_FAILED_EXT;
  const VkResult result = data->dispatch.QueueSubmit2(queue, submitCount, pSubmits, fence);
  if (result != VK_SUCCESS) history.Undo();
  return result;
}

}  // namespace asval::hooks
