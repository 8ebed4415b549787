#include "destroyed_objects.h"

namespace asval {

void DestroyedObjects::AddStructure(const Structure& structure) {
  const std::lock_guard<std::mutex> lock(mutex_);
  structures_.Add(structure);
  structures_last_.store(structure.destroyed, std::memory_order_release);
}

void DestroyedObjects::AddBuffer(const Buffer& buffer) {
  const std::lock_guard<std::mutex> lock(mutex_);
  buffers_.Add(buffer);
  buffers_last_.store(buffer.destroyed, std::memory_order_release);
}

DestroyedObjects::Answer DestroyedObjects::StructureDestroyedSince(VkAccelerationStructureKHR as, Between between,
                                                                   Structure* found) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return structures_.Find(
      between, [&](const Structure& s) { return s.handle == as && s.created <= between.recorded_at; }, found);
}

DestroyedObjects::Answer DestroyedObjects::BufferDestroyedSince(VkDeviceAddress address, Between between,
                                                                Buffer* found) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return buffers_.Find(
      between,
      [&](const Buffer& b) {
        return b.bound != 0 && b.bound <= between.recorded_at && address >= b.address && address - b.address < b.size;
      },
      found);
}

}  // namespace asval
