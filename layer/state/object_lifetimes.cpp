#include "object_lifetimes.h"

namespace asval {

void ObjectLifetimes::AddStructure(const Structure& structure) {
  const std::lock_guard<std::mutex> lock(mutex_);
  structures_.Add(structure);
  RaiseTo(structures_last_, structure.destroyed);
}

void ObjectLifetimes::AddBuffer(const Buffer& buffer) {
  const std::lock_guard<std::mutex> lock(mutex_);
  buffers_.Add(buffer);
  RaiseTo(buffers_last_, buffer.destroyed);
}

ObjectLifetimes::Answer ObjectLifetimes::StructureDestroyedSince(VkAccelerationStructureKHR as, Between between,
                                                                 Structure* found) const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return structures_.Find(
      between, [&](const Structure& s) { return s.handle == as && s.created <= between.recorded_at; }, found);
}

ObjectLifetimes::Answer ObjectLifetimes::BufferDestroyedSince(VkDeviceAddress address, Between between,
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
