// Submissions: the operations of each submitted command buffer are applied to the structures' histories in
// submission order and checked, each against what the operations before it left (HistorySubmission,
// layer/state/submission.h; the rules: SubmitChecks, layer/checks/submit_checks.h). A finding whose callback
// returns VK_TRUE keeps the whole submission from the driver, as the Khronos layer does, and its history
// changes are undone; so are those of a submission the driver rejects. In protect mode (withhold.h) so does any
// error found at submission, and a submitted command buffer that lacks a command the layer withheld.
#include "layer_data.h"
#include "submission.h"
#include "submit_checks.h"
#include "vk_intercepts.h"
#include "withhold.h"

namespace asval::hooks {

namespace {

// for_each_command_buffer(visit) calls visit(cb, location) for every submitted command buffer, in order.
template <typename ForEachCommandBuffer, typename Downcall>
VkResult Submit(DeviceData& data, const char* function, VkQueue queue, VkFence fence,
                ForEachCommandBuffer&& for_each_command_buffer, Downcall&& downcall) {
  // Captures of earlier submissions that completed are read first: a command buffer submitted again reuses
  // its capture memory (capture_tracker.h).
  ProcessCaptures(data, CaptureTracker::Covered{});
  if (data.reporter->protects() && WithholdSubmission(data, function, queue, for_each_command_buffer)) {
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const CheckContext ctx = MakeCheckContext(data);
  HistorySubmission submission(data.state);
  SubmitChecks checks(ctx);
  for_each_command_buffer(
      [&](VkCommandBuffer cb, const Location& loc) { submission.Apply(cb, checks.For(cb, loc)); });
  submission.EndApply();
  const ProtectScope protect(data.reporter->protects());
  if (checks.ReportAll()) {
    submission.Undo();
    if (protect.withheld()) {
      RecordWithheldSubmission(data.state);
      ReportWithheldSubmission(ctx, function, queue, protect);
    }
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // Pre-record: the recordings whose captures run now count as pending before the device may write them.
  // Without a fence of the app's, the layer's own goes down in its place and tells when the bytes are there.
  const bool captures = data.capture_tracker && !submission.captures().empty();
  VkFence layer_fence = VK_NULL_HANDLE;
  if (captures) {
    data.capture_tracker->Reserve(submission.captures());
    if (!fence) layer_fence = data.capture_tracker->TakeFence();
  }
  const VkResult result = downcall(fence ? fence : layer_fence);
  if (result != VK_SUCCESS) {
    if (captures) {
      data.capture_tracker->Unreserve(submission.captures());
      data.capture_tracker->ReturnFence(layer_fence);
    }
    submission.Undo();
  } else if (captures) {
    data.capture_tracker->Track(queue, fence, layer_fence, std::move(submission.captures()));
  }
  return result;
}

}  // namespace

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue queue, uint32_t submitCount, const VkSubmitInfo* pSubmits,
                                           VkFence fence) {
  DeviceData* data = GetDeviceData(queue);
  return Submit(
      *data, "vkQueueSubmit", queue, fence,
      [&](auto&& visit) {
        const Location root("vkQueueSubmit");
        for (uint32_t i = 0; i < submitCount; ++i) {
          for (uint32_t j = 0; j < pSubmits[i].commandBufferCount; ++j) {
            visit(pSubmits[i].pCommandBuffers[j], root.Field("pSubmits", i).Field("pCommandBuffers", j));
          }
        }
      },
      [&](VkFence down_fence) { return data->dispatch.QueueSubmit(queue, submitCount, pSubmits, down_fence); });
}

// Also vkQueueSubmit2KHR (the generated intercept table maps the alias here).
VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue queue, uint32_t submitCount, const VkSubmitInfo2* pSubmits,
                                            VkFence fence) {
  DeviceData* data = GetDeviceData(queue);
  return Submit(
      *data, "vkQueueSubmit2", queue, fence,
      [&](auto&& visit) {
        const Location root("vkQueueSubmit2");
        for (uint32_t i = 0; i < submitCount; ++i) {
          for (uint32_t j = 0; j < pSubmits[i].commandBufferInfoCount; ++j) {
            visit(pSubmits[i].pCommandBufferInfos[j].commandBuffer,
                  root.Field("pSubmits", i).Field("pCommandBufferInfos", j).Field("commandBuffer"));
          }
        }
      },
      [&](VkFence down_fence) { return data->dispatch.QueueSubmit2(queue, submitCount, pSubmits, down_fence); });
}

}  // namespace asval::hooks
