#pragma once
// The buffers the capture's copies read from (issue 25, item 6). A command the layer records into the app's command
// buffer may name only objects whose lifetime the layer controls: the app may destroy any of its buffers while a
// command buffer whose builds read device addresses stays valid to resubmit (another buffer over the same memory
// keeps the addresses valid), and a copy naming the destroyed buffer would then make the command buffer invalid.
// So the copies read through a buffer of the layer's own, bound to the app's VkDeviceMemory at offset 0: one per
// memory object, made the first time a capture copies from it, destroyed when the app frees the memory (before
// the downcall: every command that read the memory has completed then, VUID-vkFreeMemory-memory-00677) and at
// vkDestroyDevice. Every call goes to the next element of the chain.
//
// Memory the layer may not bind a buffer to (MemoryState::layer_may_bind: protected, exported, imported, or a
// dedicated allocation) gets no alias. A dedicated allocation for a buffer is read through that buffer: the only
// one that can ever be bound there, so a command buffer that reads its addresses is invalid once it is destroyed.
//
// Threads: the lookup is one shard of a ConcurrentMap (an immutable record, published once). Creation and
// destruction take this object's mutex; creation finds the memory in the shadow state under it, and vkFreeMemory
// erases the memory's record before it destroys the alias, so an alias is never bound to freed memory.
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>
#include <vector>

#include "concurrent_map.h"
#include "device_state.h"
#include "vk_dispatch_table.h"

namespace asval {

struct MemoryAlias {
  // The layer's TRANSFER_SRC buffer bound at offset 0; null where there is none (MemoryState::layer_may_bind
  // false, or the layer's calls failed).
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize size = 0;  // the bytes of the memory it covers, from offset 0
  // A dedicated allocation's buffer (MemoryState::dedicated_buffer): the capture reads that buffer itself.
  VkBuffer dedicated_to = VK_NULL_HANDLE;
};

class MemoryAliases {
 public:
  // `queue_families`: the families the device has queues of (the alias is shared by them all, CONCURRENT, when
  // there are several); `max_buffer_size`: the largest buffer the device allows (VUID-VkBufferCreateInfo-size-06409).
  MemoryAliases(VkDevice device, const DeviceDispatchTable& next, std::vector<uint32_t> queue_families,
                VkDeviceSize max_buffer_size);
  ~MemoryAliases();
  MemoryAliases(const MemoryAliases&) = delete;
  MemoryAliases& operator=(const MemoryAliases&) = delete;

  // The alias record of `memory`, made now when there is none; null when the memory is unknown to the layer (or
  // being freed) or the record could not be allocated.
  std::shared_ptr<const MemoryAlias> Of(const DeviceState& state, VkDeviceMemory memory);
  // The alias record of `memory` if one was made (none is made here).
  std::shared_ptr<const MemoryAlias> Find(VkDeviceMemory memory) const {
    std::optional<std::shared_ptr<const MemoryAlias>> found = aliases_.find(memory);
    return found ? std::move(*found) : nullptr;
  }
  // vkFreeMemory, before the downcall and after the shadow state forgot the memory: its alias is destroyed.
  void Forget(VkDeviceMemory memory);
  // vkDestroyBuffer: a dedicated allocation's buffer, which copies name, may be gone.
  void BufferDestroyed() { epoch_.fetch_add(1, std::memory_order_acq_rel); }
  // Changes each time a buffer a copy may name can have been destroyed (Forget, BufferDestroyed): a copy planned
  // at one epoch still names live buffers while the epoch reads the same (capture_run.h: the copies of a run are
  // recorded after the build commands that planned them).
  uint64_t Epoch() const { return epoch_.load(std::memory_order_acquire); }
  // vkDestroyDevice: every alias destroyed; none made afterwards.
  void Shutdown();
  // Aliases alive (buffers of the layer's), for the footprint and the tests' reasoning.
  std::size_t Live() const;
  // Failures of the layer's own calls (a buffer not made or not bound): such memory is not read by copies.
  uint64_t failures() const { return failures_.load(std::memory_order_relaxed); }

 private:
  std::shared_ptr<const MemoryAlias> Make(const MemoryState& memory);
  VkBuffer CreateBound(const MemoryState& memory, VkDeviceSize* size);

  const VkDevice device_;
  const DeviceDispatchTable& next_;
  const std::vector<uint32_t> queue_families_;
  const VkDeviceSize max_buffer_size_;
  ConcurrentMap<VkDeviceMemory, std::shared_ptr<const MemoryAlias>> aliases_;
  mutable std::mutex mutex_;  // creation, destruction, live_
  std::size_t live_ = 0;
  bool shut_down_ = false;
  std::atomic<uint64_t> failures_{0};
  std::atomic<uint64_t> epoch_{0};
};

}  // namespace asval
