#pragma once
// What the history rules keep per device: the structures' histories (with serialized bytes and property-query
// slots), the query pools, host operations still deferred, and the order of submissions. (The operations each
// command buffer records are in command_buffers.h.)
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "capture_log.h"
#include "command_buffer_ops.h"
#include "concurrent_map.h"
#include "history.h"
#include "submission_order.h"

namespace asval {

struct QueryPoolState {
  VkQueryType type = VK_QUERY_TYPE_OCCLUSION;
  uint32_t count = 0;
};

// Host operations of one VkDeferredOperationKHR, applied when the operation is seen to complete successfully.
struct DeferredHostOps {
  OpBatch batch;
  std::vector<std::shared_ptr<CaptureLog>> captures;  // what the batch's captured builds point into
};

struct HistoryState {
  HistoryStore store;
  // Held by a submission that changes histories from before it applies them until its downcall returned (and
  // its changes were undone, if the driver rejected it): a submission on another queue waits, so it is never
  // checked against changes of a submission that did not happen. Recursive: an app callback that reports a
  // finding of the submission may itself submit on this thread. Taken before store's lock, never after.
  std::recursive_mutex submission_order;
  // Which submitted batches the device can have run, by their semaphores (guarded by submission_order).
  SubmissionOrder order;
  ConcurrentMap<VkQueryPool, QueryPoolState> query_pools;

  // Deferred host operations (vkBuildAccelerationStructuresKHR and the host copies with a deferredOperation
  // that returned VK_OPERATION_DEFERRED_KHR). Guarded by deferred_mutex.
  mutable std::mutex deferred_mutex;
  std::unordered_map<VkDeferredOperationKHR, std::unique_ptr<DeferredHostOps>, HandleHash<VkDeferredOperationKHR>>
      deferred;
};

}  // namespace asval
