#pragma once
// A map from non-null handles to 32-bit indices, for the history store's records (history.h), which every
// operation applied at vkQueueSubmit looks up: open addressing with linear probing in one flat array (a lookup is
// one multiplication and, at a load of at most one half, one or two adjacent slots), where std::unordered_map
// walks a bucket's linked nodes and rehashes each one it meets. Deletion shifts the following entries back instead
// of leaving tombstones, so a long run of creations and destructions never slows lookups down.
//
// The home slot is the top bits of the key times 2^64 / golden ratio (Fibonacci hashing): handles are pointers
// (16-byte aligned) or counters, whose low bits say little, and the multiplication carries every bit of the key
// into the top ones.
//
// Not synchronized: the store's mutex guards it.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace asval {

class HandleIndex {
 public:
  static constexpr uint32_t kNone = UINT32_MAX;

  // The index stored for key, kNone when absent. key 0 (VK_NULL_HANDLE) is never stored.
  uint32_t Find(uint64_t key) const {
    if (key == 0 || slots_.empty()) return kNone;
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = Home(key);; i = (i + 1) & mask) {
      if (slots_[i].key == key) return slots_[i].value;
      if (slots_[i].key == 0) return kNone;
    }
  }

  // Stores key -> value; key must be non-null and absent.
  void Insert(uint64_t key, uint32_t value) {
    if ((size_ + 1) * 2 > slots_.size()) Grow();
    const std::size_t mask = slots_.size() - 1;
    std::size_t i = Home(key);
    while (slots_[i].key != 0) i = (i + 1) & mask;
    slots_[i] = Slot{key, value};
    ++size_;
  }

  // Removes key; false when absent.
  bool Erase(uint64_t key) {
    if (key == 0 || slots_.empty()) return false;
    const std::size_t mask = slots_.size() - 1;
    std::size_t hole = Home(key);
    while (slots_[hole].key != key) {
      if (slots_[hole].key == 0) return false;
      hole = (hole + 1) & mask;
    }
    // Backward shift: an entry after the hole moves into it when its home is not between the hole and itself
    // (cyclically), so that every entry stays reachable from its home without crossing an empty slot.
    for (std::size_t next = (hole + 1) & mask; slots_[next].key != 0; next = (next + 1) & mask) {
      const std::size_t home = Home(slots_[next].key);
      const bool stays = hole <= next ? (hole < home && home <= next) : (hole < home || home <= next);
      if (stays) continue;
      slots_[hole] = slots_[next];
      hole = next;
    }
    slots_[hole] = Slot{};
    --size_;
    return true;
  }

  std::size_t size() const { return size_; }

 private:
  struct Slot {
    uint64_t key = 0;  // 0: empty
    uint32_t value = 0;
  };

  std::size_t Home(uint64_t key) const { return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ULL) >> shift_); }

  void Grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    slots_.assign(old.empty() ? 64 : old.size() * 2, Slot{});
    shift_ = 64;
    for (std::size_t n = slots_.size(); n > 1; n >>= 1) --shift_;
    size_ = 0;
    for (const Slot& s : old) {
      if (s.key != 0) Insert(s.key, s.value);
    }
  }

  std::vector<Slot> slots_;
  std::size_t size_ = 0;
  unsigned shift_ = 64;  // 64 - log2(slots_.size())
};

}  // namespace asval
