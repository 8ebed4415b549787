#pragma once
// Work the device may still be executing (issue 29): the batches of submissions whose command buffers use
// acceleration structures, buffers and memory, by handle or by device address. A destroy or free of what such a
// batch uses, before that batch completed, breaks the rule that all submitted commands referring to the object
// must have completed execution (vkDestroyAccelerationStructureKHR-02442, vkDestroyBuffer-00922,
// vkFreeMemory-00677): the device reads or writes freed memory.
//
// When a batch completed. The layer reports only what the device itself says is not done: a batch is pending when
// the fence of its submission (the app's, or the layer's own passed down when the app gave none) reads unsignaled
// at the destroy, after a short grace wait (a semaphore signal of the same submission comes before its fence
// signal: an app that learned of completion through it may be a moment ahead of the fence), and no timeline value
// that the batch or a later batch of its submission signals is reached. A batch is complete once the app waited for
// it (its fence, or a later one of its queue: fences of one queue signal in submission order; its queue or the
// device idle) or reset or destroyed its fence, and once its fence or timeline values read signaled.
//
// Unknown, skipped and counted (never reported): a batch whose submission had no fence and the layer could not
// make one; a batch whose completion the host may know before its fence signals: it set an event or wrote a query
// the host read since (vkGetEventStatus, vkGetQueryPoolResults), or another queue's batch waited for a binary
// semaphore it signaled (that batch's completion says this one's semaphore signal happened, not its fence's).
//
// Guarded by one mutex; Empty() is one atomic load, so that destroys and waits cost nothing while no such work is
// in flight. Fences are polled through the dispatch table given at construction (the layer's own calls; the app's
// fence only while it names the submission: the app resets or destroys it only after a wait, FenceRetired).
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "build_activity.h"
#include "command_buffers.h"
#include "submission_order.h"
#include "vk_dispatch_table.h"

namespace asval {

struct InFlightBatch {
  uint64_t serial = 0;  // DeviceState::NextObjectId() at submission: objects bound or created later are not its
  VkQueue queue = VK_NULL_HANDLE;
  const char* function = nullptr;  // vkQueueSubmit or vkQueueSubmit2
  uint32_t submit_index = 0;       // pSubmits[submit_index]
  VkFence fence = VK_NULL_HANDLE;  // its submission's (the app's, or own_fence); null: none
  bool own_fence = false;          // the layer's: given back to the pool once it reads signaled
  bool complete = false;           // known complete (waited for, or its fence retired)
  bool host_may_know = false;      // its completion may be known before its fence signals: skipped, counted
  // What its command buffers do, in order (each a published recording: immutable).
  std::vector<std::shared_ptr<const RecordedOps>> recorded;
  // Top-level structures its traces and ray queries read through bound descriptors, with what the build they read
  // referenced (traced_tops.h; family traces: a bottom level destroyed, or its memory freed, while such a trace is
  // pending). Distinct by references; usually empty.
  struct TracedTop {
    VkAccelerationStructureKHR top = VK_NULL_HANDLE;
    const AsOp* op = nullptr;  // the first trace reading it (in `recorded`)
    std::shared_ptr<const ReferencedStructures> references;
  };
  std::vector<TracedTop> traced_tops;
  // Timeline values signaled by this batch or a later batch of its submission: reached, it completed.
  std::vector<SemaphoreUse> timeline_signals;
  // Binary semaphores it (or a later batch of its submission) signals: waited on another queue, host_may_know.
  std::vector<VkSemaphore> binary_signals;
};

// Why a pending batch's use of an object was not judged.
struct InFlightSkips {
  uint64_t no_fence = 0;       // no fence tells whether it is done
  uint64_t host_may_know = 0;  // the host may know it is done before its fence signals
};

class InFlight {
 public:
  InFlight(VkDevice device, const DeviceDispatchTable& next) : device_(device), next_(next) {}
  ~InFlight();
  InFlight(const InFlight&) = delete;
  InFlight& operator=(const InFlight&) = delete;

  // Nothing in flight: one atomic load.
  bool Empty() const { return count_.load(std::memory_order_acquire) == 0; }

  // The batches of one submission about to go down, filled by the caller (entries reuse retired ones' capacity).
  // Commit them once the submission succeeded with `fence` (the app's, or one of TakeFence: own); Abandon otherwise.
  InFlightBatch& Stage(std::vector<InFlightBatch>& staging);
  void Commit(std::vector<InFlightBatch>& staging, VkFence fence, bool own);
  void Abandon(std::vector<InFlightBatch>& staging);
  // A fence of the layer's to pass down with a submission the app gave none (null: none could be made).
  VkFence TakeFence();
  // A fence of TakeFence that did not go down (the submission failed: destroyed, its state unknown).
  void ReturnFence(VkFence fence);

  // The app waited: every batch on `queue` (null: every queue) completed.
  void QueueIdle(VkQueue queue);
  // The app's wait (waitAll) or poll of these fences returned VK_SUCCESS: their batches completed, and every earlier
  // batch of their queues.
  void FencesSignaled(uint32_t count, const VkFence* fences);
  // vkResetFences / vkDestroyFence: the app's fence no longer names its batches, which completed.
  void FenceRetired(VkFence fence);
  // vkDestroySemaphore: the batches that signal it completed (the app may destroy it only then), and the handle no
  // longer names them (it is not polled again).
  void SemaphoreDestroyed(VkSemaphore semaphore);
  // Another submission on `queue` waits for a binary semaphore: a batch of another queue that signals it may be
  // seen complete through that submission.
  void BinaryWaited(VkQueue queue, VkSemaphore semaphore);
  // The host read an event or query results: any batch in flight may have set or written it.
  void HostReadDeviceProgress();

  // Calls visit(const InFlightBatch&) for each batch that the device says is still running (its fence unsignaled
  // after the grace wait, its timeline values unreached) and that was submitted before `serial` (objects made
  // later are not what it uses). Batches found complete are retired; those that cannot be judged are counted in
  // *skips. `maybe(const InFlightBatch&)`: whether the batch may use the object at all (only those are polled).
  template <typename Maybe, typename Visit>
  void ForEachRunning(Maybe&& maybe, Visit&& visit, InFlightSkips* skips) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (InFlightBatch& b : batches_) {
      if (b.complete || !maybe(static_cast<const InFlightBatch&>(b))) continue;
      if (!b.fence) {
        ++skips->no_fence;
        continue;
      }
      if (!StillRunning(b)) continue;
      if (b.host_may_know) {
        ++skips->host_may_know;
        continue;
      }
      visit(static_cast<const InFlightBatch&>(b));
    }
    RetireCompleted();
  }
  // visit runs with the set's lock held: it must not report (an app callback may call Vulkan), only note what to.
  // Retires the batches whose fences read signaled (at each submission and wait).
  void Poll();
  // vkDestroyDevice (after the device is idle): everything completed.
  void DeviceIdle() { QueueIdle(VK_NULL_HANDLE); }
  // Called with an own fence before it is reset for reuse (the capture tracker polls it as the app's fence).
  void SetFenceRecycledCallback(void (*callback)(void* context, VkFence fence), void* context) {
    recycled_ = callback;
    recycled_context_ = context;
  }
  std::size_t size() const { return count_.load(std::memory_order_acquire); }
  // A destroy or free the layer kept from the driver (the app's callback or protect mode skipped it while the
  // device still uses the object): called once every batch submitted before `serial` completed, or at the latest
  // when this set is destroyed (vkDestroyDevice: the device is idle). Throws std::bad_alloc.
  // `buffer` and `memory`: a buffer kept alive this way and the memory it is bound to (null otherwise): freeing that
  // memory now would free what the work still uses through the buffer (DeferredBufferOn).
  void Defer(uint64_t serial, std::function<void()> destroy, VkBuffer buffer = VK_NULL_HANDLE,
             VkDeviceMemory memory = VK_NULL_HANDLE);
  // A buffer bound to `memory` whose destroy is kept back (Defer), or null.
  VkBuffer DeferredBufferOn(VkDeviceMemory memory) const;

 private:
  // With the lock: polls b's fence (after a grace wait when it reads unsignaled) and its timeline values; marks it
  // complete, and the earlier batches of its queue, when one reads signaled.
  bool StillRunning(InFlightBatch& b);
  void CompleteUpTo(std::size_t index);
  // With the lock: drops completed batches whose own fence can be reused (it reads signaled), in order.
  void RetireCompleted();

  const VkDevice device_;
  const DeviceDispatchTable& next_;
  mutable std::mutex mutex_;
  std::deque<InFlightBatch> batches_;  // submission order
  std::vector<InFlightBatch> spare_;   // retired entries, their vectors' capacity kept
  std::vector<VkFence> free_fences_;
  struct Deferred {
    uint64_t serial = 0;
    std::function<void()> destroy;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
  };
  std::vector<Deferred> deferred_;
  std::atomic<std::size_t> count_{0};
  void (*recycled_)(void*, VkFence) = nullptr;
  void* recycled_context_ = nullptr;
};

}  // namespace asval
