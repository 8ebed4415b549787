#include "capture_pool.h"

#include <algorithm>
#include <new>

#include "failure_injection.h"

namespace asval {

namespace {

uint32_t PickMemoryType(const VkPhysicalDeviceMemoryProperties& memory, uint32_t allowed) {
  constexpr VkMemoryPropertyFlags kNeeded = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  uint32_t fallback = UINT32_MAX;
  for (uint32_t t = 0; t < memory.memoryTypeCount; ++t) {
    if (!(allowed & (1u << t))) continue;
    const VkMemoryPropertyFlags flags = memory.memoryTypes[t].propertyFlags;
    if ((flags & kNeeded) != kNeeded) continue;
    if (flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT) return t;
    if (fallback == UINT32_MAX) fallback = t;
  }
  return fallback;
}

}  // namespace

CapturePool::CapturePool(VkDevice device, const DeviceDispatchTable& next,
                         const VkPhysicalDeviceMemoryProperties& memory, bool reduce, bool gather)
    : device_(device), next_(next) {
  memory_type_ = PickMemoryType(memory, ~0u);
  // Null: the capture copies, and gathers nothing.
  if (reduce || gather) reducer_ = CaptureReducer::Create(device, next, memory_type_);
  reduces_ = reduce && reducer_ != nullptr;
  gathers_ = gather && reducer_ != nullptr;
}

CapturePool::~CapturePool() { Shutdown(); }

bool CapturePool::Create(VkDeviceSize bytes, CaptureSlab* slab) {
  if (memory_type_ == UINT32_MAX || !next_.CreateBuffer || !next_.AllocateMemory || !next_.MapMemory) return false;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = bytes;
  // TRANSFER_SRC: a secondary executed twice by one primary has its first execution's captures copied out of
  // the slab before the second writes it again (capture_saves.h).
  info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               (reducer_ ? VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT : 0);
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  CaptureSlab s;
  s.size = bytes;
  if (next_.CreateBuffer(device_, &info, nullptr, &s.buffer) != VK_SUCCESS) return false;
  if (InjectedFailure(FailSite::kCaptureMemory)) {  // the test hook: as if vkAllocateMemory ran out of memory
    next_.DestroyBuffer(device_, s.buffer, nullptr);
    return false;
  }
  VkMemoryRequirements requirements{};
  next_.GetBufferMemoryRequirements(device_, s.buffer, &requirements);
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = memory_type_;
  VkMemoryAllocateFlagsInfo address_flag{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  address_flag.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  if (reducer_) allocate.pNext = &address_flag;
  void* mapped = nullptr;
  if (!(requirements.memoryTypeBits & (1u << memory_type_)) ||
      next_.AllocateMemory(device_, &allocate, nullptr, &s.memory) != VK_SUCCESS) {
    next_.DestroyBuffer(device_, s.buffer, nullptr);
    return false;
  }
  if (next_.BindBufferMemory(device_, s.buffer, s.memory, 0) != VK_SUCCESS ||
      next_.MapMemory(device_, s.memory, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) {
    next_.DestroyBuffer(device_, s.buffer, nullptr);
    next_.FreeMemory(device_, s.memory, nullptr);
    return false;
  }
  s.mapped = static_cast<uint8_t*>(mapped);
  if (reducer_) {
    // Not in the table (full): this slab's captures are copied.
    VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    address.buffer = s.buffer;
    s.address = next_.GetBufferDeviceAddress(device_, &address);
    s.table_index = reducer_->Register(s.address);
  }
  *slab = s;
  return true;
}

void CapturePool::Destroy(const CaptureSlab& slab) {
  next_.DestroyBuffer(device_, slab.buffer, nullptr);
  next_.FreeMemory(device_, slab.memory, nullptr);  // unmaps
}

bool CapturePool::Take(VkDeviceSize bytes, CaptureSlab* slab) {
  const VkDeviceSize wanted = std::max(bytes, kSlabBytes);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shut_down_) return false;
    for (std::size_t k = 0; k < free_.size(); ++k) {
      if (free_[k].size >= bytes) {
        *slab = free_[k];
        free_[k] = free_.back();
        free_.pop_back();
        peak_in_use_ = std::max(peak_in_use_, all_.size() - free_.size());
        return true;
      }
    }
  }
  {
    // Room for the new slab in both lists before it exists: a slab not listed would outlive the device, and
    // Return (called by a capture log's destructor) must never allocate.
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      all_.reserve(all_.size() + 1);
      free_.reserve(all_.size() + 1);
    } catch (const std::bad_alloc&) {
      return false;  // no slab: the capture is skipped and counted
    }
  }
  if (!Create(wanted, slab)) return false;
  std::lock_guard<std::mutex> lock(mutex_);
  try {
    all_.push_back(*slab);  // another thread's slab may have taken the room reserved above
    free_.reserve(all_.size());
  } catch (const std::bad_alloc&) {
    if (all_.empty() || all_.back().buffer != slab->buffer) {
      Destroy(*slab);
      return false;
    }
  }
  peak_in_use_ = std::max(peak_in_use_, all_.size() - free_.size());
  return true;
}

void CapturePool::AddFootprint(CaptureFootprint* out) {
  std::lock_guard<std::mutex> lock(mutex_);
  out->slabs += all_.size();
  out->slabs_in_use += all_.size() - free_.size();
  for (const CaptureSlab& slab : all_) out->slab_bytes += slab.size;
  out->peak_slabs_in_use += peak_in_use_;
}

void CapturePool::Return(const CaptureSlab& slab) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shut_down_) return;  // destroyed with the device already
  // Never allocates (a capture log's destructor calls it): the room is reserved when a slab is made. Without it
  // (a reservation that failed) the slab is not reused, only destroyed with the others at Shutdown.
  if (free_.size() == free_.capacity()) return;
  free_.push_back(slab);
}

VkEvent CapturePool::TakeEvent() {
  if (!next_.CreateEvent || !next_.DestroyEvent || !next_.CmdSetEvent || !next_.CmdWaitEvents ||
      !next_.CmdResetEvent) {
    return VK_NULL_HANDLE;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (shut_down_) return VK_NULL_HANDLE;
  if (!free_events_.empty()) {
    const VkEvent event = free_events_.back();
    free_events_.pop_back();
    return event;
  }
  // Room in both lists first, as for slabs: ReturnEvent never allocates, and no event outlives the device.
  try {
    all_events_.reserve(all_events_.size() + 1);
    free_events_.reserve(all_events_.size() + 1);
  } catch (const std::bad_alloc&) {
    return VK_NULL_HANDLE;
  }
  VkEventCreateInfo info{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
  VkEvent event = VK_NULL_HANDLE;
  if (next_.CreateEvent(device_, &info, nullptr, &event) != VK_SUCCESS) return VK_NULL_HANDLE;
  all_events_.push_back(event);
  return event;
}

void CapturePool::ReturnEvent(VkEvent event) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shut_down_ || free_events_.size() == free_events_.capacity()) return;  // destroyed at Shutdown
  free_events_.push_back(event);
}

void CapturePool::Shutdown() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (shut_down_) return;
  shut_down_ = true;
  for (const CaptureSlab& slab : all_) Destroy(slab);
  all_.clear();
  free_.clear();
  for (VkEvent event : all_events_) next_.DestroyEvent(device_, event, nullptr);
  all_events_.clear();
  free_events_.clear();
  reducer_.reset();  // its module and layout, before the device goes
}

}  // namespace asval
