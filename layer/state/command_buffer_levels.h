#pragma once
// What the record-time checks need to know about a command buffer itself: its level and whether it is a
// protected command buffer (allocated from a pool created with VK_COMMAND_POOL_CREATE_PROTECTED_BIT; the
// build commands' commandBuffer-09547 forbids those). Filled by layer/loader/command_buffer_level_hooks.cpp.
//
// Records are small values (no shared_ptr): they never change after vkAllocateCommandBuffers, so a reader
// copies one out under the shard's shared lock and needs nothing else.
#include <vulkan/vulkan.h>

#include <atomic>

#include "concurrent_map.h"

namespace asval {

struct CommandBufferInfo {
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBufferLevel level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  bool is_protected = false;
};

struct CommandBufferLevels {
  // Pool -> its create flags (VK_COMMAND_POOL_CREATE_PROTECTED_BIT is the one that matters here).
  ConcurrentMap<VkCommandPool, VkCommandPoolCreateFlags> pools;
  ConcurrentMap<VkCommandBuffer, CommandBufferInfo> buffers;
  // Set once the first protected pool is created. Until then no command buffer can be protected, so the
  // build commands' check is a single relaxed load and no map lookup: protected memory is rare.
  std::atomic<bool> any_protected_pool{false};

  // The record of a command buffer the layer saw allocated; nullopt for one it did not see.
  std::optional<CommandBufferInfo> Find(VkCommandBuffer cb) const { return buffers.find(cb); }
};

}  // namespace asval
