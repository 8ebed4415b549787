#include "command_buffer_ops_tracker.h"

#include <algorithm>

namespace asval {

std::shared_ptr<CommandBufferTracker::PoolRecord> CommandBufferTracker::PoolOf(VkCommandPool pool, bool create) {
  if (create) pools_.emplace(pool, std::make_shared<PoolRecord>());
  std::optional<std::shared_ptr<PoolRecord>> record = pools_.find(pool);
  return record ? *record : nullptr;
}

void CommandBufferTracker::Allocate(VkCommandPool pool, uint32_t count, const VkCommandBuffer* buffers) {
  std::shared_ptr<PoolRecord> record = PoolOf(pool, true);
  for (uint32_t i = 0; i < count; ++i) {
    auto log = std::make_shared<CommandBufferLog>();
    log->pool = pool;
    // A recycled handle value starts with an empty log.
    logs_.insert_or_assign(buffers[i], std::move(log));
    record->buffers.push_back(buffers[i]);
  }
}

void CommandBufferTracker::Free(uint32_t count, const VkCommandBuffer* buffers) {
  for (uint32_t i = 0; i < count; ++i) {
    if (!buffers[i]) continue;  // freeing VK_NULL_HANDLE is allowed and does nothing
    std::optional<std::shared_ptr<CommandBufferLog>> log = logs_.pop(buffers[i]);
    if (!log || !*log) continue;
    if (std::shared_ptr<PoolRecord> record = PoolOf((*log)->pool, false)) {
      auto& list = record->buffers;
      auto it = std::find(list.begin(), list.end(), buffers[i]);
      if (it != list.end()) {
        *it = list.back();
        list.pop_back();
      }
    }
  }
}

void CommandBufferTracker::ResetPool(VkCommandPool pool) {
  std::shared_ptr<PoolRecord> record = PoolOf(pool, false);
  if (!record) return;
  for (VkCommandBuffer cb : record->buffers) {
    if (std::shared_ptr<CommandBufferLog> log = Find(cb)) log->Clear();
  }
}

void CommandBufferTracker::DestroyPool(VkCommandPool pool) {
  std::optional<std::shared_ptr<PoolRecord>> record = pools_.pop(pool);
  if (!record || !*record) return;
  for (VkCommandBuffer cb : (*record)->buffers) logs_.erase(cb);
}

}  // namespace asval
