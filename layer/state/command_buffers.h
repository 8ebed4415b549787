#pragma once
// Per-command-buffer shadow state: one CommandBufferState per command buffer (its pool, level, protected-ness,
// the acceleration-structure operations it records and the secondaries it executes) in one map, and the pools
// that own them.
//
// Threads. A command buffer's recording (`recording`, `calls`, `secondaries`) is written only by the thread that
// records it: the app must externally synchronize the command buffer (and its pool) while it begins, records,
// ends, resets or frees it. Other threads read what a command buffer does when it is submitted or executed by a
// primary, and neither vkQueueSubmit's nor vkCmdExecuteCommands' command buffers are externally synchronized:
// another thread may be re-recording one at that moment (an app bug, but never a data race in the layer). So
// readers never look at the recording: vkEndCommandBuffer publishes it as an immutable RecordedOps, and readers
// take that snapshot under the command buffer's own small mutex (one lock per end, execute and submitted
// command buffer; none per recorded command).
#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include "bound_structures.h"
#include "capture_log.h"
#include "capture_run.h"
#include "command_buffer_ops.h"
#include "concurrent_map.h"
#include "protect_marks.h"

namespace asval {

// What one completed recording of a command buffer does to acceleration structures.
struct RecordedOps {
  OpBatch batch;
  // Some operation could not be recorded (allocation failure, or a secondary the layer does not know was
  // executed): what this command buffer does to structures is unknown.
  bool lost = false;
  // The capture logs its operations refer to (AsOp::capture_log): its own and those of the secondaries it
  // executes. Held here so that they live as long as a submission may read them.
  std::vector<std::shared_ptr<CaptureLog>> capture_logs;
};

class CommandBufferState {
 public:
  CommandBufferState(VkCommandPool owner, VkCommandBufferLevel buffer_level, bool in_protected_pool)
      : pool(owner), level(buffer_level), is_protected(in_protected_pool) {}

  // Fixed at allocation.
  const VkCommandPool pool;
  const VkCommandBufferLevel level;
  const bool is_protected;  // allocated from a pool created with VK_COMMAND_POOL_CREATE_PROTECTED_BIT

  // ---- the recording thread only ----
  OpBatch recording;
  bool recording_lost = false;
  // Secondaries executed by vkCmdExecuteCommands, in order (the capture of execution-time data follows them).
  std::vector<VkCommandBuffer> secondaries;
  // What this recording captures (layer/capture; made at its first capture), and the logs of the executed
  // secondaries' recordings.
  std::shared_ptr<CaptureLog> capture_log;
  std::vector<std::shared_ptr<CaptureLog>> executed_capture_logs;
  // The captures planned into capture_log by the build commands since the last capture point, not yet recorded
  // (capture_run.h).
  CaptureRun capture_run;
  // The app's compute pipeline bound now (tracked only where the capture reduces on the device): bound again
  // after the layer's reducing dispatch. Null: none bound yet in this recording, or the binding became undefined
  // (vkCmdExecuteCommands).
  VkPipeline compute_pipeline = VK_NULL_HANDLE;
  // Family traces: the pipelines, sets and pushed structures bound for trace and ray-query work.
  BoundStructures bound_structures;
  // Begun with VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT: executions of this recording may overlap, so its
  // capture points do not wait on events (one execution's set could release another's wait).
  bool simultaneous_use = false;
  // The recording's capture log, made on its first capture with slabs from `owner`.
  CaptureLog& CaptureLogFor(const std::shared_ptr<CaptureSlabOwner>& owner) {
    if (!capture_log) {
      if (spare_log_ && spare_log_->owner() == owner) {
        capture_log = std::move(spare_log_);
      } else {
        capture_log = std::make_shared<CaptureLog>(owner);
      }
      spare_log_.reset();
      capture_log->ReserveRecords(last_capture_log_size_);
    }
    return *capture_log;
  }
  // 1-based ordinal of the next call of `command`, for messages ("the 3rd vkCmd...").
  uint32_t NextOrdinal(OpCommand command) { return ++calls_[static_cast<std::size_t>(command)]; }
  // vkBeginCommandBuffer, vkResetCommandBuffer, vkResetCommandPool: empty recording, nothing published.
  void Reset();
  // vkEndCommandBuffer: the recording becomes what submissions and primaries see. False when it became lost here
  // (its snapshot could not be made: an allocation failure), a lost recording published instead.
  bool Publish();

  // ---- any thread ----
  // The operations of the last completed recording; null when it has none (or the command buffer is being
  // recorded again).
  std::shared_ptr<const RecordedOps> Executable() const {
    std::lock_guard<std::mutex> lock(published_mutex_);
    return published_;
  }
  // The command withheld from the last completed recording (or from the one in progress: a submission of a command
  // buffer that is recording is invalid, and must not run either); null when none was.
  std::shared_ptr<const WithheldCommand> Withheld() const {
    std::lock_guard<std::mutex> lock(published_mutex_);
    return published_withheld_;
  }
  // Protect mode withheld a command of the recording: the command buffer is marked at once (the first command
  // is kept), until it is reset or begun again.
  void MarkWithheld(std::shared_ptr<const WithheldCommand> command);

 private:
  std::array<uint32_t, kOpCommandCount> calls_{};
  CaptureLog::Size last_capture_log_size_;  // the last recording's log (CaptureLogFor reserves as much)
  mutable std::mutex published_mutex_;
  std::shared_ptr<const RecordedOps> published_;
  std::shared_ptr<const WithheldCommand> published_withheld_;
  // A published snapshot nobody else holds any more, kept so that the next Publish reuses its storage: a
  // command buffer re-recorded every frame allocates nothing in the steady state.
  std::shared_ptr<RecordedOps> spare_;
  std::shared_ptr<CaptureLog> spare_log_;  // the last recording's log, emptied (Reset), for the next one
};

class CommandBufferMap {
 public:
  void CreatePool(VkCommandPool pool, VkCommandPoolCreateFlags flags);
  // Forgets the pool and its command buffers (before the driver frees them: afterwards their handles may be
  // handed out again by another thread's allocation, whose records must not be erased here).
  // `freed(VkCommandBuffer)` is called for each of its command buffers (their names end with them).
  template <typename Freed>
  void DestroyPool(VkCommandPool pool, Freed&& freed) {
    std::optional<std::shared_ptr<PoolState>> record = pools_.pop(pool);
    if (!record || !*record) return;
    for (VkCommandBuffer cb : (*record)->buffers) {
      if (std::optional<std::shared_ptr<CommandBufferState>> state = buffers_.pop(cb); state && *state) {
        (*state)->capture_run.Close();
      }
      freed(cb);
    }
  }
  void ResetPool(VkCommandPool pool);
  void Allocate(const VkCommandBufferAllocateInfo& info, const VkCommandBuffer* buffers);
  void Free(uint32_t count, const VkCommandBuffer* buffers);
  // vkBeginCommandBuffer, vkResetCommandBuffer (after success): the recording starts empty.
  void Reset(VkCommandBuffer cb) {
    if (std::shared_ptr<CommandBufferState> state = Find(cb)) state->Reset();
  }
  // vkBeginCommandBuffer (after success): Reset, and the recording's usage.
  void Begin(VkCommandBuffer cb, VkCommandBufferUsageFlags usage) {
    if (std::shared_ptr<CommandBufferState> state = Find(cb)) {
      state->Reset();
      state->simultaneous_use = (usage & VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT) != 0;
    }
  }
  // vkEndCommandBuffer (after success): the recording becomes what submissions and primaries see.
  void End(VkCommandBuffer cb);
  // Protect mode withheld a command recorded into cb (protect_marks.h). A command buffer the layer never saw
  // allocated cannot be marked (false): its submissions are not withheld.
  bool MarkWithheld(VkCommandBuffer cb, std::shared_ptr<const WithheldCommand> command);
  // vkCmdExecuteCommands: a primary that executes a marked secondary is marked with the secondary's command.
  void InheritWithheld(VkCommandBuffer primary, uint32_t count, const VkCommandBuffer* secondaries);
  // The command that marks cb, or null. A single load while no command buffer of the device was ever marked.
  std::shared_ptr<const WithheldCommand> Withheld(VkCommandBuffer cb) const;
  // Where allocation failures are counted (DeviceState's: failure_counters.h); set once, at device creation.
  void SetFailureCounters(FailureCounters* failures) { failures_ = failures; }

  // The state of a command buffer, or null when the layer never saw it allocated.
  std::shared_ptr<CommandBufferState> Find(VkCommandBuffer cb) const {
    std::optional<std::shared_ptr<CommandBufferState>> found = buffers_.find(cb);
    return found ? *found : nullptr;
  }
  // Set once the first protected pool is created. Until then no command buffer can be protected, so the build
  // commands' commandBuffer-09547 is a single load and no map lookup: protected memory is rare.
  bool AnyProtectedPool() const { return any_protected_pool_.load(std::memory_order_acquire); }
  std::size_t size() const { return buffers_.size(); }
  // Every command buffer's state (footprint.h counts what they hold).
  std::vector<std::shared_ptr<CommandBufferState>> All() const {
    std::vector<std::shared_ptr<CommandBufferState>> out;
    for (auto& [cb, state] : buffers_.snapshot()) out.push_back(std::move(state));
    return out;
  }
  // Changes to the set of command buffers so far (allocations, frees, pool destruction): while it reads the
  // same, a CommandBufferState found before is still the one the map holds (history_recorder.cpp keeps the
  // last one it recorded into).
  StampValue stamp() const { return buffers_.stamp(); }
  // How many command buffers hold a run of build commands whose captures are not recorded yet (capture_run.h):
  // while none does, the commands that end a run look up no command buffer.
  std::atomic<uint32_t>& open_capture_runs() const { return open_capture_runs_; }
  bool AnyOpenCaptureRun() const { return open_capture_runs_.load(std::memory_order_acquire) != 0; }

 private:
  struct PoolState {
    VkCommandPoolCreateFlags flags = 0;
    // Written only under the app's external synchronization of the pool.
    std::vector<VkCommandBuffer> buffers;
  };
  std::shared_ptr<PoolState> PoolOf(VkCommandPool pool) const;

  void CountUntracked(uint32_t count) const;

  FailureCounters* failures_ = nullptr;
  mutable std::atomic<uint32_t> open_capture_runs_{0};  // before buffers_: outlives every state the map holds
  ConcurrentMap<VkCommandBuffer, std::shared_ptr<CommandBufferState>, 6> buffers_;
  ConcurrentMap<VkCommandPool, std::shared_ptr<PoolState>> pools_;
  std::atomic<bool> any_protected_pool_{false};
  // Set at the first MarkWithheld: until then submissions look up no command buffer for protect mode.
  std::atomic<bool> any_withheld_{false};
};

}  // namespace asval
