#include "buffer_memo.h"

#include <memory>
#include <optional>

namespace asval {

namespace {

KnownBuffer FromRecord(const BufferState& record, VkDeviceAddress base, VkDeviceSize size) {
  return KnownBuffer{record.handle, base, size, record.usage, record.bound, record.memory, record.memory_offset};
}

}  // namespace

const KnownBuffer* BufferMemo::HeldSlow(const DeviceState& state, VkDeviceAddress address, VkDeviceSize bytes,
                                        VkBufferUsageFlags usage) {
  for (int k = 0; k < count_; ++k) {
    if (Serves(entries_[k], address, bytes, usage)) {
      before_ = last_;
      last_ = k;
      return &entries_[k];
    }
  }
  // The candidate the address map accepts is the one whose record the predicate saw: keep that record.
  std::shared_ptr<const BufferState> accepted;
  const std::optional<AddressHit> hit = state.buffer_addresses.FindCovering(address, bytes, [&](VkBuffer buffer) {
    std::optional<std::shared_ptr<const BufferState>> record = state.buffers.find(buffer);
    if (!record || !*record || ((*record)->usage & usage) != usage) return false;
    accepted = std::move(*record);
    return true;
  });
  if (!hit || !accepted) return nullptr;
  before_ = last_;
  last_ = Remember(FromRecord(*accepted, hit->base, hit->size));
  return &entries_[last_];
}

bool BufferMemo::Find(const DeviceState& state, VkBuffer buffer, KnownBuffer* out) {
  for (int k = 0; k < count_; ++k) {
    if (entries_[k].buffer == buffer) {
      *out = entries_[k];
      return true;
    }
  }
  const std::optional<std::shared_ptr<const BufferState>> record = state.buffers.find(buffer);
  if (!record || !*record) return false;
  // The address range is only known to the address map; an entry found by handle serves handle lookups.
  const BufferState& r = **record;
  *out = FromRecord(r, 0, 0);
  if (r.device_address != 0) {
    out->base = r.device_address;
    out->size = r.size;
  }
  Remember(*out);
  return true;
}

int BufferMemo::Remember(const KnownBuffer& entry) {
  if (count_ < kEntries) {
    entries_[count_] = entry;
    return count_++;
  }
  const int slot = next_;
  entries_[slot] = entry;
  next_ = (next_ + 1) % kEntries;
  return slot;
}

}  // namespace asval
