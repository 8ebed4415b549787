#pragma once
// Per-command-buffer operation logs. The map lookup takes a shard's lock; the log itself is written without
// one, because the application must externally synchronize a command buffer (and its pool) while it records,
// resets or frees it, and may not record it while it is pending. Submission only reads logs.
// (Levels and protected-ness live in command_buffer_levels.h; the same allocation hooks fill both.)
#include <vulkan/vulkan.h>

#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "command_buffer_ops.h"
#include "concurrent_map.h"

namespace asval {

struct CommandBufferLog {
  VkCommandPool pool = VK_NULL_HANDLE;
  OpBatch batch;
  // Calls of each command recorded so far, for the ordinals in messages ("the 3rd vkCmd...").
  std::array<uint32_t, kOpCommandCount> calls{};
  // An operation could not be recorded (allocation failure): what this command buffer does is unknown.
  bool lost = false;

  uint32_t NextOrdinal(OpCommand command) { return ++calls[static_cast<std::size_t>(command)]; }
  void Clear() {
    batch.Clear();
    calls.fill(0);
    lost = false;
  }
};

class CommandBufferTracker {
 public:
  void Allocate(VkCommandPool pool, uint32_t count, const VkCommandBuffer* buffers);
  void Free(uint32_t count, const VkCommandBuffer* buffers);
  void ResetPool(VkCommandPool pool);
  void DestroyPool(VkCommandPool pool);

  // The log of a command buffer, or null when the layer never saw it allocated.
  std::shared_ptr<CommandBufferLog> Find(VkCommandBuffer cb) const {
    std::optional<std::shared_ptr<CommandBufferLog>> log = logs_.find(cb);
    return log ? *log : nullptr;
  }
  std::size_t size() const { return logs_.size(); }

 private:
  // The command buffers of a pool, so that vkResetCommandPool / vkDestroyCommandPool reach them. Written only
  // under the app's external synchronization of the pool.
  struct PoolRecord {
    std::vector<VkCommandBuffer> buffers;
  };
  std::shared_ptr<PoolRecord> PoolOf(VkCommandPool pool, bool create);

  ConcurrentMap<VkCommandBuffer, std::shared_ptr<CommandBufferLog>, 6> logs_;
  ConcurrentMap<VkCommandPool, std::shared_ptr<PoolRecord>> pools_;
};

}  // namespace asval
