#include "memory_aliases.h"

#include <algorithm>
#include <new>

namespace asval {

MemoryAliases::MemoryAliases(VkDevice device, const DeviceDispatchTable& next, std::vector<uint32_t> queue_families,
                             VkDeviceSize max_buffer_size)
    : device_(device), next_(next), queue_families_(std::move(queue_families)), max_buffer_size_(max_buffer_size) {}

MemoryAliases::~MemoryAliases() { Shutdown(); }

std::shared_ptr<const MemoryAlias> MemoryAliases::Of(const DeviceState& state, VkDeviceMemory memory) {
  if (std::optional<std::shared_ptr<const MemoryAlias>> found = aliases_.find(memory)) return std::move(*found);
  std::lock_guard<std::mutex> lock(mutex_);
  if (std::optional<std::shared_ptr<const MemoryAlias>> found = aliases_.find(memory)) return std::move(*found);
  if (shut_down_) return nullptr;
  // Under the mutex: vkFreeMemory erases the record before it takes the mutex to destroy the alias, so an alias
  // made here is either destroyed by that free or made for memory that is still allocated.
  const std::optional<std::shared_ptr<const MemoryState>> record = state.memories.find(memory);
  if (!record || !*record) return nullptr;  // unknown to the layer: not read (counted by the capture)
  try {
    std::shared_ptr<const MemoryAlias> made = Make(**record);
    if (made && made->buffer != VK_NULL_HANDLE) {
      try {
        aliases_.insert_or_assign(memory, made);
      } catch (const std::bad_alloc&) {
        next_.DestroyBuffer(device_, made->buffer, nullptr);
        return nullptr;
      }
      ++live_;
    } else if (made) {
      aliases_.insert_or_assign(memory, made);  // no buffer: the answer is kept, never asked for again
    }
    return made;
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}

std::shared_ptr<const MemoryAlias> MemoryAliases::Make(const MemoryState& memory) {
  auto alias = std::make_shared<MemoryAlias>();
  alias->dedicated_to = memory.dedicated_buffer;
  if (!memory.layer_may_bind) return alias;
  VkDeviceSize size = 0;
  alias->buffer = CreateBound(memory, &size);
  alias->size = size;
  if (alias->buffer == VK_NULL_HANDLE) failures_.fetch_add(1, std::memory_order_relaxed);
  return alias;
}

// A TRANSFER_SRC buffer over as much of the memory as one buffer may cover, bound at offset 0 (which meets every
// alignment), or null. Its memory requirements must fit in the allocation (VUID-vkBindBufferMemory-size-01037)
// and allow its memory type (memory-01035): a buffer of the whole allocation may need more than the allocation
// where the size is not a multiple of the buffer's alignment, so that case is tried once more, rounded down.
VkBuffer MemoryAliases::CreateBound(const MemoryState& memory, VkDeviceSize* size) {
  if (!next_.CreateBuffer || !next_.DestroyBuffer || !next_.GetBufferMemoryRequirements || !next_.BindBufferMemory) {
    return VK_NULL_HANDLE;
  }
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  // Any queue of the device may run a command buffer with the layer's copy: no ownership to transfer.
  if (queue_families_.size() > 1) {
    info.sharingMode = VK_SHARING_MODE_CONCURRENT;
    info.queueFamilyIndexCount = static_cast<uint32_t>(queue_families_.size());
    info.pQueueFamilyIndices = queue_families_.data();
  } else {
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  }
  info.size = std::min(memory.size, max_buffer_size_);
  for (int attempt = 0; attempt < 2 && info.size != 0; ++attempt) {
    VkBuffer buffer = VK_NULL_HANDLE;
    if (next_.CreateBuffer(device_, &info, nullptr, &buffer) != VK_SUCCESS) return VK_NULL_HANDLE;
    VkMemoryRequirements requirements{};
    next_.GetBufferMemoryRequirements(device_, buffer, &requirements);
    if (requirements.size <= memory.size) {
      if (!(requirements.memoryTypeBits & (1u << memory.type_index)) ||
          next_.BindBufferMemory(device_, buffer, memory.handle, 0) != VK_SUCCESS) {
        next_.DestroyBuffer(device_, buffer, nullptr);
        return VK_NULL_HANDLE;
      }
      *size = info.size;
      return buffer;
    }
    next_.DestroyBuffer(device_, buffer, nullptr);
    if (requirements.alignment == 0) return VK_NULL_HANDLE;
    info.size = memory.size / requirements.alignment * requirements.alignment;
  }
  return VK_NULL_HANDLE;
}

void MemoryAliases::Forget(VkDeviceMemory memory) {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<std::shared_ptr<const MemoryAlias>> alias = aliases_.pop(memory);
  if (!alias || !*alias || (*alias)->buffer == VK_NULL_HANDLE) return;
  epoch_.fetch_add(1, std::memory_order_acq_rel);
  next_.DestroyBuffer(device_, (*alias)->buffer, nullptr);
  --live_;
}

void MemoryAliases::Shutdown() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shut_down_) return;
  shut_down_ = true;
  try {
    for (const auto& [memory, alias] : aliases_.snapshot()) {
      if (alias && alias->buffer != VK_NULL_HANDLE) next_.DestroyBuffer(device_, alias->buffer, nullptr);
    }
  } catch (const std::bad_alloc&) {
    // The snapshot could not be copied: the buffers go with the device (vkDestroyDevice frees what is left).
  }
  aliases_.clear();
  live_ = 0;
}

std::size_t MemoryAliases::Live() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return live_;
}

}  // namespace asval
