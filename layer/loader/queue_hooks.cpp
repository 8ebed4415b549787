// Submissions: the operations of each submitted command buffer are applied to the structures' histories in
// submission order and checked, each against what the operations before it left (HistorySubmission,
// layer/state/submission.h; the rules: SubmitChecks, layer/checks/submit_checks.h). A finding whose callback
// returns VK_TRUE keeps the whole submission from the driver, as the Khronos layer does, and its history
// changes are undone; so are those of a submission the driver rejects. In protect mode (withhold.h) so does any
// error found at submission, and a submitted command buffer that lacks a command the layer withheld: its batches
// still go down, emptied of their command buffers (synchronization_only.h), so that what waits for it completes.
// Batches are applied in an order the device can execute them in (layer/state/submission_order.h): one that waits
// for a timeline value nothing has signaled yet is deferred until a later call signals it (ordered_batches.h).
#include <mutex>
#include <new>
#include <optional>

#include "layer_data.h"
#include "ordered_batches.h"
#include "submission.h"
#include "submit_checks.h"
#include "synchronization_only.h"
#include "traced_tops.h"
#include "vk_intercepts.h"
#include "withhold.h"

namespace asval::hooks {

namespace {

// The capture logs a deferred (or unordered) command buffer's copies write, counted pending with the call's captures
// so that another submission of the same recording is not read while the device may write them (capture_tracker.h).
void HoldDeferredLogs(const RecordedOps& ops, SubmissionCaptures& captures) {
  for (const std::shared_ptr<CaptureLog>& log : ops.capture_logs) {
    bool known = false;
    for (const std::shared_ptr<CaptureLog>& held : captures.logs) known |= held == log;
    if (!known) captures.logs.push_back(log);
  }
}

// A call whose batches touch no structure's history (a sparse bind; a withheld submission's emptied batches) but whose
// semaphores order the batches that do: a batch that waits for an unsignaled value holds back what it signals, and
// the values it signals may let deferred batches run. Returns the downcall's result.
template <typename HasSemaphores, typename SemaphoresOf, typename Downcall>
VkResult PassDownInOrder(DeviceData& data, const char* function, VkQueue queue, uint32_t batch_count,
                         HasSemaphores&& has_semaphores, SemaphoresOf&& semaphores_of, Downcall&& downcall) {
  SubmissionOrder& order = data.state.history.order;
  if (!data.state.history_tracked || !(order.backlog() != 0 || (order.any_timeline() && has_semaphores()))) {
    return downcall();
  }
  std::lock_guard<std::recursive_mutex> lock(data.state.history.submission_order);
  SubmissionOrder::Call call(order, queue, function);
  for (uint32_t i = 0; i < batch_count; ++i) call.Place(semaphores_of(i));
  const VkResult result = downcall();
  if (result == VK_SUCCESS) {
    call.Commit();
    ApplyReadyBatches(data);
  }
  return result;
}

// Protect mode withheld the submission: its batches go down emptied (`emptied_downcall`), so that its fence, its
// semaphore signals and its waits complete as the app expects; it returns VK_ERROR_VALIDATION_FAILED_EXT (or the
// driver's error). Should the emptied batches not fit in memory, nothing goes down (counted).
template <typename HasSemaphores, typename SemaphoresOf, typename EmptiedDowncall>
VkResult SynchronizeWithheld(DeviceData& data, const char* function, VkQueue queue, uint32_t batch_count,
                             HasSemaphores&& has_semaphores, SemaphoresOf&& semaphores_of,
                             EmptiedDowncall&& emptied_downcall) {
  try {
    const VkResult result =
        PassDownInOrder(data, function, queue, batch_count, has_semaphores, semaphores_of, emptied_downcall);
    return result == VK_SUCCESS ? VK_ERROR_VALIDATION_FAILED_EXT : result;
  } catch (const std::bad_alloc&) {
    RecordSynchronizationLost(data.state);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
}

// Family lifetime (in_flight.h): the batches of a submission that use structures, buffers or memory, staged before
// the downcall with the semaphores through which their completion may be learned. A wait of any submission for a
// binary semaphore that a batch of another queue signals is noted (that batch may be seen complete through it).
// `submission`: the call's history submission, whose batches were all applied now (in execution order) when
// `applied_now`; the top levels their traces read are then kept with them (traced_tops.h).
template <typename SemaphoresOf, typename ForEachCommandBufferIn>
void StageInFlight(DeviceData& data, const char* function, VkQueue queue, uint32_t batch_count,
                   SemaphoresOf&& semaphores_of, ForEachCommandBufferIn&& for_each_command_buffer_in,
                   uint64_t submission, bool applied_now, std::vector<InFlightBatch>& staging) {
  InFlight& in_flight = *data.in_flight;
  SubmissionOrder& order = data.state.history.order;
  std::unique_lock<std::recursive_mutex> order_lock;  // timeline types are known under the order lock
  if (order.any_timeline()) order_lock = std::unique_lock<std::recursive_mutex>(data.state.history.submission_order);
  const auto timeline = [&](VkSemaphore s) { return order_lock.owns_lock() && order.IsTimeline(s); };
  const uint64_t serial = data.state.NextObjectId();
  const std::size_t first = staging.size();
  for (uint32_t i = 0; i < batch_count; ++i) {
    const BatchSemaphores semaphores = semaphores_of(i);
    if (!in_flight.Empty()) {
      for (uint32_t w = 0; w < semaphores.wait_count; ++w) {
        const SemaphoreUse wait = semaphores.Wait(w);
        if (!timeline(wait.semaphore)) in_flight.BinaryWaited(queue, wait.semaphore);
      }
    }
    InFlightBatch* batch = nullptr;
    for_each_command_buffer_in(i, [&](VkCommandBuffer cb, const Location&, uint32_t) {
      std::shared_ptr<const RecordedOps> ops;
      if (!RecordedOf(data.state, cb, &ops) || !ops) return;
      if (!batch) {
        batch = &in_flight.Stage(staging);
        batch->serial = serial;
        batch->queue = queue;
        batch->function = function;
        batch->submit_index = i;
      }
      batch->recorded.push_back(std::move(ops));
    });
    // Its signals, and every later batch's of the call, say it completed: added to each staged batch up to it.
    for (uint32_t g = 0; g < semaphores.signal_count; ++g) {
      const SemaphoreUse signal = semaphores.Signal(g);
      for (std::size_t k = first; k < staging.size(); ++k) {
        if (timeline(signal.semaphore)) {
          staging[k].timeline_signals.push_back(signal);
        } else {
          staging[k].binary_signals.push_back(signal.semaphore);
        }
      }
    }
  }
  if (applied_now) NoteTracedTops(data.state, submission, staging, first);
}

// semaphores_of(i): batch i's BatchSemaphores; for_each_command_buffer_in(i, visit) calls visit(cb, location, j)
// for every command buffer of batch i, in order. has_semaphores(): some batch waits or signals.
// emptied_downcall(): the call's batches without their command buffers, with its fence (SynchronizeWithheld).
template <typename HasSemaphores, typename SemaphoresOf, typename ForEachCommandBufferIn, typename Downcall,
          typename EmptiedDowncall>
VkResult Submit(DeviceData& data, const char* function, VkQueue queue, VkFence fence, uint32_t batch_count,
                HasSemaphores&& has_semaphores, SemaphoresOf&& semaphores_of,
                ForEachCommandBufferIn&& for_each_command_buffer_in, Downcall&& downcall,
                EmptiedDowncall&& emptied_downcall) {
  // Captures of earlier submissions that completed are read first: a command buffer submitted again reuses
  // its capture memory (capture_tracker.h).
  ProcessCaptures(data, CaptureTracker::Covered{});
  if (data.in_flight) data.in_flight->Poll();
  const auto for_each_command_buffer = [&](auto&& visit) {
    for (uint32_t i = 0; i < batch_count; ++i) {
      for_each_command_buffer_in(i, [&](VkCommandBuffer cb, const Location& loc, uint32_t) { visit(cb, loc); });
    }
  };
  if (data.reporter->protects() && WithholdSubmission(data, function, queue, for_each_command_buffer)) {
    return SynchronizeWithheld(data, function, queue, batch_count, has_semaphores, semaphores_of, emptied_downcall);
  }
  const CheckContext ctx = MakeCheckContext(data);
  // Execution order across queues: only a device with timeline semaphores, or with batches deferred, pays for it.
  SubmissionOrder& order = data.state.history.order;
  std::unique_lock<std::recursive_mutex> order_lock;  // declared before the submission: released after it
  std::optional<SubmissionOrder::Call> call;
  if (data.state.history_tracked && (order.backlog() != 0 || (order.any_timeline() && has_semaphores()))) {
    order_lock = std::unique_lock<std::recursive_mutex>(data.state.history.submission_order);
    call.emplace(order, queue, function);
  }
  HistorySubmission submission(data.state);
  SubmitChecks checks(ctx, submission.captures().id);
  uint64_t unordered_batches = 0, unordered_ops = 0;
  bool applied_now = true;
  for (uint32_t i = 0; i < batch_count; ++i) {
    const Placement place = call ? call->Place(semaphores_of(i)) : Placement::kNow;
    unordered_batches += place == Placement::kUnordered;
    applied_now &= place == Placement::kNow;
    for_each_command_buffer_in(i, [&](VkCommandBuffer cb, const Location& loc, uint32_t j) {
      if (place == Placement::kNow) return submission.Apply(cb, checks.For(cb, loc));
      std::shared_ptr<const RecordedOps> ops;
      if (!RecordedOf(data.state, cb, &ops)) return;
      if (place == Placement::kUnordered) unordered_ops += submission.ApplyUnordered(ops);
      if (place == Placement::kDeferred) call->Defer(cb, i, j, ops, submission.captures().id);
      if (ops && data.capture_tracker) {
        try {
          HoldDeferredLogs(*ops, submission.captures());
        } catch (const std::bad_alloc&) {
          data.state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
        }
      }
    });
  }
  submission.EndApply();
  const ProtectScope protect(data.reporter->protects());
  if (checks.ReportAll()) {
    submission.Undo();
    if (!protect.withheld()) return VK_ERROR_VALIDATION_FAILED_EXT;  // the app's VK_TRUE: a plain skip
    RecordWithheldSubmission(data.state);
    ReportWithheldSubmission(ctx, function, queue, protect);
    call.reset();  // what its batches noted is forgotten; the emptied batches are placed anew
    return SynchronizeWithheld(data, function, queue, batch_count, has_semaphores, semaphores_of, emptied_downcall);
  }
  // Pre-record: the batches that use structures, buffers or memory are staged as in flight (in_flight.h); without a
  // fence of the app's, the layer's own goes down in its place and tells when they completed.
  // This thread's staging array, kept with its capacity: a submission allocates nothing for it in the steady state
  // (nothing between staging and Commit/Abandon submits on this thread).
  thread_local std::vector<InFlightBatch> in_flight;
  VkFence in_flight_fence = VK_NULL_HANDLE;
  if (data.in_flight) {
    try {
      StageInFlight(data, function, queue, batch_count, semaphores_of, for_each_command_buffer_in,
                    submission.captures().id, applied_now, in_flight);
    } catch (const std::bad_alloc&) {
      data.state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
      data.in_flight->Abandon(in_flight);  // not tracked: their destroys are not judged
    }
    if (!fence && !in_flight.empty()) in_flight_fence = data.in_flight->TakeFence();
  }
  const bool in_flight_fenced = !fence && !in_flight.empty();  // the layer's fence is the in-flight one (or none)
  // The recordings whose captures run now count as pending before the device may write them. Without a fence of the
  // app's, the layer's own goes down in its place and tells when the bytes are there (the in-flight fence, when
  // there is one: the capture tracker polls it as the app's, and hears when it is reset for reuse).
  const SubmissionCaptures& held = submission.captures();
  const bool captures = data.capture_tracker && (!held.empty() || !held.logs.empty());
  VkFence layer_fence = VK_NULL_HANDLE;
  if (captures) {
    data.capture_tracker->Reserve(submission.captures());
    if (!fence && !in_flight_fenced) layer_fence = data.capture_tracker->TakeFence();
  }
  const VkFence down_fence = fence ? fence : in_flight_fence ? in_flight_fence : layer_fence;
  const VkResult result = downcall(down_fence);
  if (result != VK_SUCCESS) {
    if (captures) {
      data.capture_tracker->Unreserve(submission.captures());
      data.capture_tracker->ReturnFence(layer_fence);
    }
    if (data.in_flight) {
      data.in_flight->Abandon(in_flight);
      data.in_flight->ReturnFence(in_flight_fence);
    }
    submission.Undo();
    return result;  // the call's deferred batches are forgotten, its signals undone (~Call)
  }
  if (data.in_flight) data.in_flight->Commit(in_flight, fence ? fence : in_flight_fence, !fence);
  if (captures) {
    data.capture_tracker->Track(queue, fence ? fence : in_flight_fence, layer_fence, std::move(submission.captures()));
  }
  if (call) {
    call->Commit();
    order.counters.batches_unordered.fetch_add(unordered_batches, std::memory_order_relaxed);
    order.counters.operations_unordered.fetch_add(unordered_ops, std::memory_order_relaxed);
    // What this call signaled may let deferred batches run: they execute after it, so they are applied after it.
    ApplyReadyBatches(data);
  }
  return result;
}

}  // namespace

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue queue, uint32_t submitCount, const VkSubmitInfo* pSubmits,
                                           VkFence fence) {
  DeviceData* data = GetDeviceData(queue);
  const Location root("vkQueueSubmit");
  return Submit(
      *data, "vkQueueSubmit", queue, fence, submitCount,
      [&] {
        for (uint32_t i = 0; i < submitCount; ++i) {
          if (pSubmits[i].waitSemaphoreCount != 0 || pSubmits[i].signalSemaphoreCount != 0) return true;
        }
        return false;
      },
      [&](uint32_t i) { return SemaphoresOf(pSubmits[i]); },
      [&](uint32_t i, auto&& visit) {
        for (uint32_t j = 0; j < pSubmits[i].commandBufferCount; ++j) {
          visit(pSubmits[i].pCommandBuffers[j], root.Field("pSubmits", i).Field("pCommandBuffers", j), j);
        }
      },
      [&](VkFence down_fence) { return data->dispatch.QueueSubmit(queue, submitCount, pSubmits, down_fence); },
      [&] {
        const EmptiedSubmits emptied(submitCount, pSubmits);
        return data->dispatch.QueueSubmit(queue, emptied.count(), emptied.submits(), fence);
      });
}

// Also vkQueueSubmit2KHR (the generated intercept table maps the alias here).
VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue queue, uint32_t submitCount, const VkSubmitInfo2* pSubmits,
                                            VkFence fence) {
  DeviceData* data = GetDeviceData(queue);
  const Location root("vkQueueSubmit2");
  return Submit(
      *data, "vkQueueSubmit2", queue, fence, submitCount,
      [&] {
        for (uint32_t i = 0; i < submitCount; ++i) {
          if (pSubmits[i].waitSemaphoreInfoCount != 0 || pSubmits[i].signalSemaphoreInfoCount != 0) return true;
        }
        return false;
      },
      [&](uint32_t i) { return SemaphoresOf(pSubmits[i]); },
      [&](uint32_t i, auto&& visit) {
        for (uint32_t j = 0; j < pSubmits[i].commandBufferInfoCount; ++j) {
          visit(pSubmits[i].pCommandBufferInfos[j].commandBuffer,
                root.Field("pSubmits", i).Field("pCommandBufferInfos", j).Field("commandBuffer"), j);
        }
      },
      [&](VkFence down_fence) { return data->dispatch.QueueSubmit2(queue, submitCount, pSubmits, down_fence); },
      [&] {
        const EmptiedSubmits2 emptied(submitCount, pSubmits);
        return data->dispatch.QueueSubmit2(queue, emptied.count(), emptied.submits(), fence);
      });
}

// Sparse binding touches no structure's history, but its semaphores order the batches that do.
VKAPI_ATTR VkResult VKAPI_CALL QueueBindSparse(VkQueue queue, uint32_t bindInfoCount, const VkBindSparseInfo* pBindInfo,
                                               VkFence fence) {
  DeviceData* data = GetDeviceData(queue);
  return PassDownInOrder(
      *data, "vkQueueBindSparse", queue, bindInfoCount,
      [&] {
        for (uint32_t i = 0; i < bindInfoCount; ++i) {
          if (pBindInfo[i].waitSemaphoreCount != 0 || pBindInfo[i].signalSemaphoreCount != 0) return true;
        }
        return false;
      },
      [&](uint32_t i) { return SemaphoresOf(pBindInfo[i]); },
      [&] { return data->dispatch.QueueBindSparse(queue, bindInfoCount, pBindInfo, fence); });
}

}  // namespace asval::hooks
