#include "command_buffers.h"

#include <algorithm>

namespace asval {

void CommandBufferState::Reset() {
  recording.Clear();
  recording_lost = false;
  secondaries.clear();
  capture_log.reset();  // a submission still reading it keeps it
  executed_capture_logs.clear();
  compute_pipeline = VK_NULL_HANDLE;
  calls_.fill(0);
  std::shared_ptr<const RecordedOps> old;
  {
    std::lock_guard<std::mutex> lock(published_mutex_);
    old.swap(published_);
  }
  // Nobody else can obtain it now; if nobody holds it either, its storage is ours to reuse.
  if (old && old.use_count() == 1) spare_ = std::const_pointer_cast<RecordedOps>(std::move(old));
}

void CommandBufferState::Publish() {
  std::shared_ptr<const RecordedOps> snapshot;
  if (!recording.empty() || recording_lost) {
    // (A recording with captures always has the operations that refer to them.)
    std::shared_ptr<RecordedOps> fresh = spare_ ? std::move(spare_) : std::make_shared<RecordedOps>();
    fresh->batch.Swap(recording);  // the recording takes the spare's (cleared) storage
    recording.Clear();
    fresh->batch.RememberSnapshots();
    fresh->lost = recording_lost;
    fresh->capture_logs = executed_capture_logs;
    if (capture_log) fresh->capture_logs.push_back(capture_log);
    snapshot = std::move(fresh);
  }
  std::lock_guard<std::mutex> lock(published_mutex_);
  published_ = std::move(snapshot);
}

std::shared_ptr<CommandBufferMap::PoolState> CommandBufferMap::PoolOf(VkCommandPool pool) const {
  std::optional<std::shared_ptr<PoolState>> record = pools_.find(pool);
  return record ? *record : nullptr;
}

void CommandBufferMap::CreatePool(VkCommandPool pool, VkCommandPoolCreateFlags flags) {
  auto record = std::make_shared<PoolState>();
  record->flags = flags;
  pools_.insert_or_assign(pool, std::move(record));
  if (flags & VK_COMMAND_POOL_CREATE_PROTECTED_BIT) any_protected_pool_.store(true, std::memory_order_release);
}

void CommandBufferMap::DestroyPool(VkCommandPool pool) {
  std::optional<std::shared_ptr<PoolState>> record = pools_.pop(pool);
  if (!record || !*record) return;
  for (VkCommandBuffer cb : (*record)->buffers) buffers_.erase(cb);
}

void CommandBufferMap::ResetPool(VkCommandPool pool) {
  std::shared_ptr<PoolState> record = PoolOf(pool);
  if (!record) return;
  for (VkCommandBuffer cb : record->buffers) {
    if (std::shared_ptr<CommandBufferState> state = Find(cb)) state->Reset();
  }
}

void CommandBufferMap::Allocate(const VkCommandBufferAllocateInfo& info, const VkCommandBuffer* buffers) {
  std::shared_ptr<PoolState> pool = PoolOf(info.commandPool);
  const bool is_protected = pool && (pool->flags & VK_COMMAND_POOL_CREATE_PROTECTED_BIT);
  for (uint32_t i = 0; i < info.commandBufferCount; ++i) {
    // insert_or_assign: a recycled handle value starts afresh.
    buffers_.insert_or_assign(buffers[i], std::make_shared<CommandBufferState>(info.commandPool, info.level,
                                                                               is_protected));
    if (pool) pool->buffers.push_back(buffers[i]);
  }
}

void CommandBufferMap::Free(uint32_t count, const VkCommandBuffer* buffers) {
  for (uint32_t i = 0; i < count; ++i) {
    if (!buffers[i]) continue;  // freeing VK_NULL_HANDLE is allowed and does nothing
    std::optional<std::shared_ptr<CommandBufferState>> state = buffers_.pop(buffers[i]);
    if (!state || !*state) continue;
    if (std::shared_ptr<PoolState> pool = PoolOf((*state)->pool)) {
      auto& list = pool->buffers;
      auto it = std::find(list.begin(), list.end(), buffers[i]);
      if (it != list.end()) {
        *it = list.back();
        list.pop_back();
      }
    }
  }
}

}  // namespace asval
