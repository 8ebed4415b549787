#include "command_buffers.h"

#include <algorithm>
#include <new>

#include "failure_injection.h"

namespace asval {

namespace {

// What a recording whose snapshot could not be made publishes: lost (its submissions make every structure's
// history unknown). Static and not owned (an aliasing pointer): publishing it allocates nothing.
std::shared_ptr<const RecordedOps> LostRecording() {
  static const RecordedOps lost = [] {
    RecordedOps ops;
    ops.lost = true;
    return ops;
  }();
  return std::shared_ptr<const RecordedOps>(std::shared_ptr<const RecordedOps>(), &lost);
}

}  // namespace

void CommandBufferState::Reset() {
  recording.Clear();
  recording_lost = false;
  secondaries.clear();
  if (capture_log) last_capture_log_size_ = capture_log->RecordCounts();
  std::shared_ptr<CaptureLog> last_log = std::move(capture_log);  // a submission still reading it keeps it
  capture_run.Close();  // its reservations were in that log
  executed_capture_logs.clear();
  compute_pipeline = VK_NULL_HANDLE;
  bound_structures.Reset();
  simultaneous_use = false;
  calls_.fill(0);
  std::shared_ptr<const RecordedOps> old;
  {
    std::lock_guard<std::mutex> lock(published_mutex_);
    old.swap(published_);
    published_withheld_.reset();
  }
  // Nobody else can obtain it now; if nobody holds it either, its storage is ours to reuse.
  if (old && old.use_count() == 1) {
    spare_ = std::const_pointer_cast<RecordedOps>(std::move(old));
    spare_->capture_logs.clear();  // the logs are let go now, not at the next Publish
  }
  // Likewise the last recording's log, once no submission reads it: its slabs and events go back to the pool, its
  // vectors are kept (a recording of hundreds of builds would otherwise allocate them anew every frame, where the
  // allocator's large requests cost tens of thousands of instructions).
  if (last_log && last_log.use_count() == 1) {
    last_log->Recycle();
    spare_log_ = std::move(last_log);
  }
}

bool CommandBufferState::Publish() {
  std::shared_ptr<const RecordedOps> snapshot;
  bool published = true;
  if (!recording.empty() || recording_lost) {
    try {
      InjectBadAlloc(FailSite::kRecording);
      // (A recording with captures always has the operations that refer to them.)
      std::shared_ptr<RecordedOps> fresh = spare_ ? std::move(spare_) : std::make_shared<RecordedOps>();
      fresh->batch.Swap(recording);  // the recording takes the spare's (cleared) storage
      recording.Clear();
      fresh->batch.RememberSnapshots();
      fresh->lost = recording_lost;
      fresh->capture_logs = executed_capture_logs;
      if (capture_log) fresh->capture_logs.push_back(capture_log);
      snapshot = std::move(fresh);
    } catch (const std::bad_alloc&) {
      // The capture log stays held here until the command buffer is reset, which the app may do only once no
      // submission of it is pending: the device never writes into slabs given back.
      recording.Clear();
      snapshot = LostRecording();
      published = recording_lost;  // already lost (and counted) or lost now
      recording_lost = true;
    }
  }
  std::lock_guard<std::mutex> lock(published_mutex_);
  published_ = std::move(snapshot);
  return published;
}

void CommandBufferState::MarkWithheld(std::shared_ptr<const WithheldCommand> command) {
  std::lock_guard<std::mutex> lock(published_mutex_);
  if (!published_withheld_) published_withheld_ = std::move(command);
}

std::shared_ptr<CommandBufferMap::PoolState> CommandBufferMap::PoolOf(VkCommandPool pool) const {
  std::optional<std::shared_ptr<PoolState>> record = pools_.find(pool);
  return record ? *record : nullptr;
}

void CommandBufferMap::CreatePool(VkCommandPool pool, VkCommandPoolCreateFlags flags) {
  // Before anything can fail: a protected pool unknown to the layer must still switch commandBuffer-09547 on.
  if (flags & VK_COMMAND_POOL_CREATE_PROTECTED_BIT) any_protected_pool_.store(true, std::memory_order_release);
  try {
    InjectBadAlloc(FailSite::kObjectRecord);
    auto record = std::make_shared<PoolState>();
    record->flags = flags;
    pools_.insert_or_assign(pool, std::move(record));
  } catch (const std::bad_alloc&) {
    // Unknown pool: its command buffers are still tracked one by one (not protected, freed one by one; those a
    // destruction of the pool frees linger until their handle values are allocated again).
    pools_.erase(pool);
    CountUntracked(1);
  }
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
  uint32_t untracked = 0;
  for (uint32_t i = 0; i < info.commandBufferCount; ++i) {
    bool listed = false;
    try {
      InjectBadAlloc(FailSite::kObjectRecord);
      if (pool) {
        pool->buffers.push_back(buffers[i]);
        listed = true;
      }
      // insert_or_assign: a recycled handle value starts afresh.
      buffers_.insert_or_assign(buffers[i], std::make_shared<CommandBufferState>(info.commandPool, info.level,
                                                                                 is_protected));
    } catch (const std::bad_alloc&) {
      // Unknown command buffer: its submissions make every structure's history unknown (submission.h), and a
      // stale record of a recycled handle value must not stand in for it.
      if (listed) pool->buffers.pop_back();
      buffers_.erase(buffers[i]);
      ++untracked;
    }
  }
  CountUntracked(untracked);
}

void CommandBufferMap::CountUntracked(uint32_t count) const {
  if (count == 0 || !failures_) return;
  failures_->allocation_failures.fetch_add(count, std::memory_order_relaxed);
  failures_->objects_untracked.fetch_add(count, std::memory_order_relaxed);
}

void CommandBufferMap::End(VkCommandBuffer cb) {
  std::shared_ptr<CommandBufferState> state = Find(cb);
  if (!state || state->Publish() || !failures_) return;
  failures_->allocation_failures.fetch_add(1, std::memory_order_relaxed);
  failures_->recordings_lost.fetch_add(1, std::memory_order_relaxed);
}

void CommandBufferMap::Free(uint32_t count, const VkCommandBuffer* buffers) {
  for (uint32_t i = 0; i < count; ++i) {
    if (!buffers[i]) continue;  // freeing VK_NULL_HANDLE is allowed and does nothing
    std::optional<std::shared_ptr<CommandBufferState>> state = buffers_.pop(buffers[i]);
    if (!state || !*state) continue;
    (*state)->capture_run.Close();
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

bool CommandBufferMap::MarkWithheld(VkCommandBuffer cb, std::shared_ptr<const WithheldCommand> command) {
  const std::shared_ptr<CommandBufferState> state = Find(cb);
  if (!state) return false;
  any_withheld_.store(true, std::memory_order_release);
  state->MarkWithheld(std::move(command));
  return true;
}

void CommandBufferMap::InheritWithheld(VkCommandBuffer primary, uint32_t count, const VkCommandBuffer* secondaries) {
  if (!any_withheld_.load(std::memory_order_acquire) || !secondaries) return;
  for (uint32_t i = 0; i < count; ++i) {
    if (std::shared_ptr<const WithheldCommand> command = Withheld(secondaries[i])) {
      MarkWithheld(primary, std::move(command));
      return;
    }
  }
}

std::shared_ptr<const WithheldCommand> CommandBufferMap::Withheld(VkCommandBuffer cb) const {
  if (!any_withheld_.load(std::memory_order_acquire)) return nullptr;
  const std::shared_ptr<CommandBufferState> state = Find(cb);
  return state ? state->Withheld() : nullptr;
}

}  // namespace asval
