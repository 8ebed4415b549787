#include "buffer_memo.h"

#include <memory>
#include <optional>

namespace asval {

namespace {

KnownBuffer FromRecord(const BufferState& record, VkDeviceAddress base, VkDeviceSize size) {
  return KnownBuffer{record.handle, record.id, base, size, record.usage, record.bound, record.memory,
                     record.memory_offset};
}

}  // namespace

const KnownBuffer* BufferMemo::HeldSlow(const DeviceState& state, VkDeviceAddress address, VkDeviceSize bytes,
                                        VkBufferUsageFlags usage) {
  const unsigned slot = SlotOf(address);
  if (const int e = address_entries_[slot] - 1; e >= 0 && address_keys_[slot] == address &&
                                               Serves(entries_[e], address, bytes, usage)) {
    return Answer(e);
  }
  for (int k = 0; k < count_; ++k) {
    if (Serves(entries_[k], address, bytes, usage)) {
      address_keys_[slot] = address;
      address_entries_[slot] = static_cast<uint8_t>(k + 1);
      return Answer(k);
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
  const int e = Remember(FromRecord(*accepted, hit->base, hit->size));
  address_keys_[slot] = address;
  address_entries_[slot] = static_cast<uint8_t>(e + 1);
  return Answer(e);
}

bool BufferMemo::Find(const DeviceState& state, VkBuffer buffer, KnownBuffer* out) {
  const auto key = reinterpret_cast<uint64_t>(buffer);
  const unsigned slot = SlotOf(key);
  if (const int e = handle_entries_[slot] - 1; e >= 0 && handle_keys_[slot] == key && entries_[e].buffer == buffer) {
    *out = entries_[e];
    last_found_ = static_cast<uint8_t>(e);
    return true;
  }
  for (int k = 0; k < count_; ++k) {
    if (entries_[k].buffer == buffer) {
      handle_keys_[slot] = key;
      handle_entries_[slot] = static_cast<uint8_t>(k + 1);
      *out = entries_[k];
      last_found_ = static_cast<uint8_t>(k);
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
  const int e = Remember(*out);
  handle_keys_[slot] = key;
  handle_entries_[slot] = static_cast<uint8_t>(e + 1);
  last_found_ = static_cast<uint8_t>(e);
  return true;
}

int BufferMemo::Remember(const KnownBuffer& entry) {
  if (count_ == kEntries) Reset();  // more buffers than a call needs: start over rather than evict one by one
  entries_[count_] = entry;
  return count_++;
}

void BufferMemo::Reset() {
  count_ = 0;
  last_ = 0;
  before_ = 0;
  entries_[0] = KnownBuffer{};  // Held tries entries_[last_] and entries_[before_] before looking at count_
  address_entries_.fill(0);
  handle_entries_.fill(0);
}

}  // namespace asval
