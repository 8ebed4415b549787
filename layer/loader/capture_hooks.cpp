// Execution-time capture (issue 12): the waits through which the app learns that work completed. Each calls
// down first; once the app's wait succeeded, the submissions with captures it covers are processed (their
// captured builds' activity filled, the update rules judged on it, device deserializations verified against
// what was serialized), so that findings are reported before the app's wait returns, and a deserialized
// structure's history is restored before the app can submit work that depends on the wait.
#include <vector>

#include "activity_rules.h"
#include "capture_notices.h"
#include "history_apply.h"
#include "indirect_rules.h"
#include "instance_rules.h"
#include "layer_data.h"
#include "serialized_capture.h"
#include "vk_intercepts.h"
#include "withhold.h"

namespace asval {

void ProcessCaptures(DeviceData& data, const CaptureTracker::Covered& covered) {
  if (!data.capture_tracker || data.capture_tracker->idle()) return;
  const CheckContext ctx = MakeCheckContext(data);
  const LayerSettings& settings = data.instance->settings;
  const uint32_t warnings = settings.capture_warnings;
  const uint32_t spacing_permille = warnings & kCaptureWarnFloatSpacing ? settings.capture_float_spacing_permille : 0;
  // Protect mode: an error judged now is about work that already ran; later submissions are withheld instead.
  const ProtectScope protect(data.reporter->protects());
  data.capture_tracker->Process(covered, [&](SubmissionCaptures& done) {
    for (const std::shared_ptr<BuildActivity>& activity : done.fills) {
      activity->Fill(spacing_permille);
      ReportUndefinedInput(ctx, *activity, warnings);
      if (spacing_permille != 0) ReportCoarseSpacing(ctx, *activity, spacing_permille);
    }
    for (const ActivityComparison& update : done.comparisons) CheckUpdateActivity(ctx, update);
    for (const InstanceReferenceCheck& build : done.instance_checks) {
      // Family traces: what the top level references, for the traces that read it later (traced_structures.h).
      // Kept whether or not a pipeline reads structures yet: apps build their scene before creating pipelines too.
      const bool keep =
          data.state.traces_tracked && build.activity && build.activity->status() != BuildActivity::Status::kUnknown;
      auto referenced = keep ? std::make_shared<ReferencedStructures>() : nullptr;
      if (CheckInstanceReferences(ctx, build, referenced.get()) && referenced) {
        RememberReferencedBuilds(data.state.history.store, *referenced);
        build.activity->SetReferences(std::move(referenced));
      }
      ReportInstanceTransforms(ctx, build, warnings, spacing_permille);
    }
    for (const IndirectRangeCheck& build : done.indirect_checks) CheckIndirectRanges(ctx, build);
    // Device serialization: the content of the bytes serialized, and the deserializations verified against it
    // (layer/state writes the history; it takes the store's lock itself, under the processing lock held here).
    CompleteSerializedCaptures(data.state.history.store, data.state.capture_counters, done);
  });
  hooks::HaltSubmissionsAfter(data, protect);
}

namespace {

// The app's wait returned `result`: on success, what it covers is processed before the app sees the result.
VkResult AfterWait(DeviceData& data, VkResult result, const CaptureTracker::Covered& covered) {
  if (result == VK_SUCCESS) ProcessCaptures(data, covered);
  return result;
}

CaptureTracker::Covered Queue(VkQueue queue) {
  CaptureTracker::Covered covered;
  covered.queue = queue;
  return covered;
}

CaptureTracker::Covered Everything() {
  CaptureTracker::Covered covered;
  covered.all = true;
  return covered;
}

}  // namespace

namespace hooks {

// The waits also tell the in-flight set (family lifetime, in_flight.h) what completed.
VKAPI_ATTR VkResult VKAPI_CALL QueueWaitIdle(VkQueue queue) {
  DeviceData* data = GetDeviceData(queue);
  const VkResult result = data->dispatch.QueueWaitIdle(queue);
  if (result == VK_SUCCESS && data->in_flight) data->in_flight->QueueIdle(queue);
  return AfterWait(*data, result, Queue(queue));
}

VKAPI_ATTR VkResult VKAPI_CALL DeviceWaitIdle(VkDevice device) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.DeviceWaitIdle(device);
  if (result == VK_SUCCESS && data->in_flight) data->in_flight->DeviceIdle();
  return AfterWait(*data, result, Everything());
}

VKAPI_ATTR VkResult VKAPI_CALL WaitForFences(VkDevice device, uint32_t fenceCount, const VkFence* pFences,
                                             VkBool32 waitAll, uint64_t timeout) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.WaitForFences(device, fenceCount, pFences, waitAll, timeout);
  if (result == VK_SUCCESS && data->in_flight) {
    if (waitAll || fenceCount == 1) {
      data->in_flight->FencesSignaled(fenceCount, pFences);
    } else {
      data->in_flight->Poll();  // waitAny: the fences that signaled are found by polling
    }
  }
  if (result == VK_SUCCESS && data->capture_tracker && !data->capture_tracker->idle()) {
    CaptureTracker::Covered covered;
    std::vector<VkFence> signaled;
    if (waitAll || fenceCount == 1) {
      covered.fences = pFences;
      covered.fence_count = fenceCount;
    } else {
      // waitAny: only the fences that signaled are covered.
      for (uint32_t k = 0; k < fenceCount; ++k) {
        if (data->dispatch.GetFenceStatus(device, pFences[k]) == VK_SUCCESS) signaled.push_back(pFences[k]);
      }
      covered.fences = signaled.data();
      covered.fence_count = static_cast<uint32_t>(signaled.size());
    }
    ProcessCaptures(*data, covered);
  }
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL GetFenceStatus(VkDevice device, VkFence fence) {
  DeviceData* data = GetDeviceData(device);
  CaptureTracker::Covered covered;
  covered.fences = &fence;
  covered.fence_count = 1;
  const VkResult result = data->dispatch.GetFenceStatus(device, fence);
  if (result == VK_SUCCESS && data->in_flight) data->in_flight->FencesSignaled(1, &fence);
  return AfterWait(*data, result, covered);
}

// Semaphore waits say nothing the layer maps to its submissions: what completed by now is processed.
VKAPI_ATTR VkResult VKAPI_CALL WaitSemaphores(VkDevice device, const VkSemaphoreWaitInfo* pWaitInfo, uint64_t timeout) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.WaitSemaphores(device, pWaitInfo, timeout);
  if (result == VK_SUCCESS && data->in_flight) data->in_flight->Poll();
  return AfterWait(*data, result, CaptureTracker::Covered{});
}

VKAPI_ATTR VkResult VKAPI_CALL GetSemaphoreCounterValue(VkDevice device, VkSemaphore semaphore, uint64_t* pValue) {
  DeviceData* data = GetDeviceData(device);
  return AfterWait(*data, data->dispatch.GetSemaphoreCounterValue(device, semaphore, pValue),
                   CaptureTracker::Covered{});
}

// An event the device set tells the host that the work before it ran, before its submission's fence signals: the
// batches in flight may be known complete that early (in_flight.h: their destroys are then skipped and counted).
VKAPI_ATTR VkResult VKAPI_CALL GetEventStatus(VkDevice device, VkEvent event) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.GetEventStatus(device, event);
  if (result == VK_EVENT_SET && data->in_flight) data->in_flight->HostReadDeviceProgress();
  return result;
}

// The app may reset or destroy a fence only once the submissions it was given to completed.
VKAPI_ATTR VkResult VKAPI_CALL ResetFences(VkDevice device, uint32_t fenceCount, const VkFence* pFences) {
  DeviceData* data = GetDeviceData(device);
  if (data->capture_tracker && pFences) {
    for (uint32_t k = 0; k < fenceCount; ++k) data->capture_tracker->FenceRetired(pFences[k]);
  }
  if (data->in_flight && pFences) {
    for (uint32_t k = 0; k < fenceCount; ++k) data->in_flight->FenceRetired(pFences[k]);
  }
  return data->dispatch.ResetFences(device, fenceCount, pFences);
}

VKAPI_ATTR void VKAPI_CALL DestroyFence(VkDevice device, VkFence fence, const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  if (data->capture_tracker) data->capture_tracker->FenceRetired(fence);  // before: the handle may be reused
  if (data->in_flight) data->in_flight->FenceRetired(fence);
  data->dispatch.DestroyFence(device, fence, pAllocator);
}

}  // namespace hooks
}  // namespace asval
