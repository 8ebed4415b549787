#pragma once
// Execution order across queues (issue 25, item 8). On one queue, batches execute in submission order. Across
// queues the layer applies them in host order (the order its submission_order lock gives them), except where a
// semaphore says the device cannot: a batch that waits for a timeline value which no batch applied so far, no
// vkSignalSemaphore and not the semaphore's initial value has signaled cannot have started yet. Such a batch is
// *deferred*: its history apply, and the checks that run against it, wait until the value is signaled (by a later
// submission on another queue, or by the host), and so does every later batch on its queue and every batch that
// waits on what a deferred batch signals (timeline or binary). When the signal arrives, the deferred batches whose
// waits are met are taken in an order the device can execute them in (TakeReady) and applied by the caller.
//
// Binary semaphores need no deferral of their own: their signal is submitted before their wait (the spec), so it
// was applied already unless its batch is itself deferred.
//
// A wait on a timeline semaphore that other processes or APIs can signal (imported, or created exportable) for a
// value the layer has not seen signaled cannot be ordered: the batch is placed kUnordered, applied at once with its
// operations unknown (the caller makes every structure's history unknown; the checks are skipped and counted).
// Deferred batches still waiting at vkDestroyDevice are counted (NeverResolved).
//
// Guarded by HistoryState::submission_order (the caller holds it), except any_timeline() and backlog(), which are
// read without it so that a submission without semaphores, or on a device without timeline semaphores, pays two
// atomic loads while nothing is deferred.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include "command_buffers.h"
#include "concurrent_map.h"

namespace asval {

struct SemaphoreUse {
  VkSemaphore semaphore = VK_NULL_HANDLE;
  uint64_t value = 0;  // timeline semaphores; ignored for binary ones
};

// One batch's semaphores as the app gave them (its arrays, not copied): VkSubmitInfo with the values of a chained
// VkTimelineSemaphoreSubmitInfo, VkSubmitInfo2's VkSemaphoreSubmitInfo arrays, or VkBindSparseInfo.
struct BatchSemaphores {
  uint32_t wait_count = 0;
  uint32_t signal_count = 0;
  const VkSemaphore* waits = nullptr;
  const VkSemaphore* signals = nullptr;
  const uint64_t* wait_values = nullptr;
  uint32_t wait_value_count = 0;
  const uint64_t* signal_values = nullptr;
  uint32_t signal_value_count = 0;
  const VkSemaphoreSubmitInfo* wait_infos = nullptr;    // VkSubmitInfo2
  const VkSemaphoreSubmitInfo* signal_infos = nullptr;  // VkSubmitInfo2

  SemaphoreUse Wait(uint32_t i) const;
  SemaphoreUse Signal(uint32_t i) const;
};
BatchSemaphores SemaphoresOf(const VkSubmitInfo& submit);
BatchSemaphores SemaphoresOf(const VkSubmitInfo2& submit);
BatchSemaphores SemaphoresOf(const VkBindSparseInfo& bind);

// A command buffer of a deferred batch: what it recorded, read when it was submitted (a pending command buffer
// cannot be re-recorded, but the snapshot is held anyway), and where it was in the call (for the message).
struct DeferredCommandBuffer {
  VkCommandBuffer cb = VK_NULL_HANDLE;
  uint32_t submit_index = 0;
  uint32_t cb_index = 0;
  std::shared_ptr<const RecordedOps> ops;  // null: what it does to structures is unknown
};

struct DeferredBatch {
  uint64_t id = 0;
  VkQueue queue = VK_NULL_HANDLE;
  const char* function = nullptr;  // vkQueueSubmit or vkQueueSubmit2
  // The id of the submission that made it (SubmissionCaptures::id): objects destroyed after that call are not what
  // its command buffers' state was judged on (layer/checks/recorded_objects.h).
  uint64_t submitted_at = 0;
  std::vector<SemaphoreUse> timeline_waits;
  std::vector<uint64_t> after;  // deferred batches whose binary signals it waits for
  std::vector<SemaphoreUse> signals;
  std::vector<DeferredCommandBuffer> command_buffers;
  bool lost = false;  // a command buffer could not be kept (allocation failure): applied unknown
};

enum class Placement : uint8_t {
  kNow,        // applied now, in host order
  kDeferred,   // applied when its waits are signaled (TakeReady)
  kUnordered,  // applied now with its operations unknown: it waits on a semaphore signaled outside the layer's view
};

struct OrderCounters {
  std::atomic<uint64_t> batches_deferred{0};
  std::atomic<uint64_t> batches_unordered{0};
  std::atomic<uint64_t> operations_unordered{0};  // their operations, whose checks were skipped
  std::atomic<uint64_t> batches_never_resolved{0};
};

class SubmissionOrder {
 public:
  // Without the lock: a submission must go through Call::Place when batches are deferred (backlog()), or when it
  // has semaphores and the device has timeline semaphores; otherwise it is applied in host order, nothing noted.
  bool any_timeline() const { return timelines_.load(std::memory_order_acquire) != 0; }

  // vkCreateSemaphore of a timeline semaphore; `external`: created exportable (another process may signal it).
  void TimelineCreated(VkSemaphore semaphore, uint64_t initial_value, bool external);
  void SemaphoreDestroyed(VkSemaphore semaphore);
  // vkImportSemaphoreFdKHR: its payload is shared with whoever exported it.
  void SemaphoreImported(VkSemaphore semaphore);
  // vkSignalSemaphore succeeded.
  void Signaled(VkSemaphore semaphore, uint64_t value);
  // A timeline semaphore the layer saw created (with the lock held).
  bool IsTimeline(VkSemaphore semaphore) { return FindTimeline(semaphore) != nullptr; }

  // One vkQueueSubmit / vkQueueSubmit2 / vkQueueBindSparse call, batch by batch, with the lock held until the
  // call's downcall returned: Commit when it succeeded; otherwise the destructor forgets what Place noted.
  class Call {
   public:
    Call(SubmissionOrder& order, VkQueue queue, const char* function);
    Call(const Call&) = delete;
    Call& operator=(const Call&) = delete;
    ~Call();
    // The next batch of the call. kNow and kUnordered: its timeline signals count as signaled from now on.
    Placement Place(const BatchSemaphores& batch);
    // A command buffer of the batch Place just deferred, in order. Throws std::bad_alloc.
    // submitted_at: the submission's id (SubmissionCaptures::id), kept for the checks made when the batch is applied.
    void Defer(VkCommandBuffer cb, uint32_t submit_index, uint32_t cb_index, std::shared_ptr<const RecordedOps> ops,
               uint64_t submitted_at);
    // The downcall succeeded: the deferred batches join the backlog.
    void Commit();

   private:
    SubmissionOrder& order_;
    const VkQueue queue_;
    const char* const function_;
    bool deferring_ = false;  // a batch of this call was deferred: every later one is (same queue)
    bool committed_ = false;
    // Timeline values before this call's signals: the order's spare, borrowed when a batch signals one (a
    // steady stream of submissions allocates nothing).
    std::vector<std::pair<VkSemaphore, uint64_t>> undo_;
    std::vector<DeferredBatch> deferred_;
  };

  // The next deferred batch the device can run now (every wait met, nothing before it on its queue), taken out of
  // the backlog; *unordered when a wait on an external semaphore is still unmet (apply it unknown). False when
  // none is ready, or when this thread is applying one already (a callback that submits). After applying it, the
  // caller calls Applied.
  bool TakeReady(DeferredBatch* out, bool* unordered);
  void Applied(const DeferredBatch& batch);
  // vkDestroyDevice: batches whose waits were never signaled, counted and dropped.
  void NeverResolved();
  // Deferred batches waiting now.
  std::size_t backlog() const { return backlog_size_.load(std::memory_order_acquire); }

  OrderCounters counters;

 private:
  struct Timeline {
    uint64_t known = 0;  // the highest value signaled by what the layer applied (or the host)
    bool external = false;
  };
  Timeline* FindTimeline(VkSemaphore semaphore);
  bool SignaledByDeferred(VkSemaphore semaphore, uint64_t* id) const;
  bool InBacklog(uint64_t id) const;
  DeferredBatch MakeBatch(const BatchSemaphores& batch, VkQueue queue, const char* function);

  std::unordered_map<VkSemaphore, Timeline, HandleHash<VkSemaphore>> timeline_values_;
  std::atomic<std::size_t> timelines_{0};
  // Binary semaphores signaled by a deferred batch (its id), until that batch is applied.
  std::vector<std::pair<VkSemaphore, uint64_t>> deferred_binary_;
  std::vector<std::pair<VkSemaphore, uint64_t>> spare_undo_;
  std::deque<DeferredBatch> backlog_;  // host order
  std::atomic<std::size_t> backlog_size_{0};
  uint64_t next_id_ = 0;
  bool taking_ = false;  // TakeReady handed out a batch that is not Applied yet
};

}  // namespace asval
