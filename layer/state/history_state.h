#pragma once
// What the history rules keep per device: command-buffer operation logs, the structures' histories (with
// serialized bytes and property-query slots), the query pools, and host operations still deferred.
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>
#include <unordered_map>

#include "command_buffer_ops.h"
#include "command_buffer_ops_tracker.h"
#include "concurrent_map.h"
#include "history.h"

namespace asval {

struct QueryPoolState {
  VkQueryType type = VK_QUERY_TYPE_OCCLUSION;
  uint32_t count = 0;
};

// Host operations of one VkDeferredOperationKHR, applied when the operation is seen to complete successfully.
struct DeferredHostOps {
  OpBatch batch;
};

struct HistoryState {
  CommandBufferTracker command_buffers;
  HistoryStore store;
  ConcurrentMap<VkQueryPool, QueryPoolState> query_pools;

  // Deferred host operations (vkBuildAccelerationStructuresKHR and the host copies with a deferredOperation
  // that returned VK_OPERATION_DEFERRED_KHR). Guarded by deferred_mutex.
  std::mutex deferred_mutex;
  std::unordered_map<VkDeferredOperationKHR, std::unique_ptr<DeferredHostOps>, HandleHash<VkDeferredOperationKHR>>
      deferred;
};

}  // namespace asval
