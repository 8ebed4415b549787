// Sharded reader/writer hash map for per-object state (handle -> std::shared_ptr<State>).
//
// Written after the shape of Vulkan-Utility-Libraries' vku::concurrent::unordered_map: 2^N shards, each
// with its own lock and std::unordered_map, so threads touching different objects rarely share a lock.
// There are no iterators and no operator[]: every access copies the value out under the shard's lock, so
// no reference into a shard outlives the lock (operator[] under a read lock is the VVL bug the layer guide
// warns about).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "change_stamp.h"

namespace asval {

// 64-bit finalizer of MurmurHash3 (fmix64): every input bit flips about half of the output bits. Vulkan
// handles are pointers or counters whose low 4 bits are usually constant (16-byte alignment) and whose high
// bits rarely change, so neither the raw value nor its low bits make a usable shard index.
constexpr std::uint64_t MixBits(std::uint64_t x) noexcept {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

// Hash for handles: pointers (non-dispatchable handles on 64-bit, dispatchable handles), integers
// (non-dispatchable handles on 32-bit, addresses) and enums are mixed directly; anything else goes through
// std::hash first and is mixed afterwards.
template <typename Key>
struct HandleHash {
  std::size_t operator()(const Key& key) const noexcept {
    if constexpr (std::is_pointer_v<Key>) {
      return static_cast<std::size_t>(MixBits(reinterpret_cast<std::uintptr_t>(key)));
    } else if constexpr (std::is_integral_v<Key> || std::is_enum_v<Key>) {
      return static_cast<std::size_t>(MixBits(static_cast<std::uint64_t>(key)));
    } else {
      return static_cast<std::size_t>(MixBits(static_cast<std::uint64_t>(std::hash<Key>{}(key))));
    }
  }
};

template <typename Key, typename T, unsigned kShardsLog2 = 4, typename Hash = HandleHash<Key>>
class ConcurrentMap {
  static_assert(kShardsLog2 <= 12, "more than 4096 shards wastes memory for no gain");

 public:
  static constexpr std::size_t kShardCount = std::size_t{1} << kShardsLog2;

  // Inserts or overwrites. Returns true if the key was new.
  template <typename V>
  bool insert_or_assign(const Key& key, V&& value) {
    Shard& shard = ShardFor(key);
    std::unique_lock lock(shard.mutex);
    const bool inserted = shard.map.insert_or_assign(key, std::forward<V>(value)).second;
    stamp_.Bump();
    return inserted;
  }

  // Constructs the value only if the key is absent. Returns false (and leaves the old value) if present.
  template <typename... Args>
  bool emplace(const Key& key, Args&&... args) {
    Shard& shard = ShardFor(key);
    std::unique_lock lock(shard.mutex);
    const bool inserted = shard.map.try_emplace(key, std::forward<Args>(args)...).second;
    if (inserted) stamp_.Bump();
    return inserted;
  }

  // A copy of the value: for shared_ptr values the object stays alive after a concurrent erase.
  std::optional<T> find(const Key& key) const {
    const Shard& shard = ShardFor(key);
    std::shared_lock lock(shard.mutex);
    const auto it = shard.map.find(key);
    if (it == shard.map.end()) return std::nullopt;
    return it->second;
  }

  bool contains(const Key& key) const {
    const Shard& shard = ShardFor(key);
    std::shared_lock lock(shard.mutex);
    return shard.map.find(key) != shard.map.end();
  }

  // Returns true if the key was present.
  bool erase(const Key& key) {
    Shard& shard = ShardFor(key);
    std::unique_lock lock(shard.mutex);
    const bool erased = shard.map.erase(key) != 0;
    if (erased) stamp_.Bump();
    return erased;
  }

  // Replaces the value only while it is still `expected` (compared with ==), in one locked step: a writer that
  // derived `value` from `expected` never overwrites a change made meanwhile (an erase, a newer record).
  template <typename V>
  bool replace_if(const Key& key, const T& expected, V&& value) {
    Shard& shard = ShardFor(key);
    std::unique_lock lock(shard.mutex);
    const auto it = shard.map.find(key);
    if (it == shard.map.end() || !(it->second == expected)) return false;
    it->second = std::forward<V>(value);
    stamp_.Bump();
    return true;
  }

  // Erases and hands back the value in one locked step, so exactly one of several racing callers gets it
  // (used by vkDestroy* to take ownership of the state being destroyed).
  std::optional<T> pop(const Key& key) {
    Shard& shard = ShardFor(key);
    std::unique_lock lock(shard.mutex);
    const auto it = shard.map.find(key);
    if (it == shard.map.end()) return std::nullopt;
    std::optional<T> value(std::move(it->second));
    shard.map.erase(it);
    stamp_.Bump();
    return value;
  }

  // Copies every entry. Each shard is copied under its own lock, one at a time: the result is consistent
  // per shard, not a global instant (the same guarantee as VUL's snapshot()).
  std::vector<std::pair<Key, T>> snapshot() const {
    return snapshot([](const Key&, const T&) { return true; });
  }

  // Copies the entries for which keep(key, value) is true; keep runs under a shard's shared lock.
  template <typename Pred>
  std::vector<std::pair<Key, T>> snapshot(Pred&& keep) const {
    std::vector<std::pair<Key, T>> out;
    for (const Shard& shard : shards_) {
      std::shared_lock lock(shard.mutex);
      for (const auto& [key, value] : shard.map) {
        if (keep(key, value)) out.emplace_back(key, value);
      }
    }
    return out;
  }

  // Sum over the shards, each read under its lock: exact only when no writer runs concurrently.
  std::size_t size() const {
    std::size_t total = 0;
    for (const Shard& shard : shards_) {
      std::shared_lock lock(shard.mutex);
      total += shard.map.size();
    }
    return total;
  }

  bool empty() const { return size() == 0; }

  void clear() {
    for (Shard& shard : shards_) {
      std::unique_lock lock(shard.mutex);
      shard.map.clear();
      stamp_.Bump();
    }
  }

  // Changes so far (every insert, replacement and removal counts): equal stamps, no change in between.
  StampValue stamp() const { return stamp_.Read(); }

 private:
  // One cache line (at least) per shard, so that two threads locking neighbouring shards do not bounce
  // the same line. 64 bytes is the line size on every CPU this layer targets; the standard's
  // hardware_destructive_interference_size makes GCC warn that its value is ABI-unstable.
  struct alignas(64) Shard {
    mutable std::shared_mutex mutex;
    std::unordered_map<Key, T, Hash> map;
  };

  static std::size_t ShardIndex(const Key& key) {
    if constexpr (kShardsLog2 == 0) {
      return 0;
    } else {
      // The high bits pick the shard; the unordered_map inside uses the whole hash (reduced modulo its
      // bucket count), so the two choices stay independent enough.
      constexpr unsigned kHashBits = std::numeric_limits<std::size_t>::digits;
      return Hash{}(key) >> (kHashBits - kShardsLog2);
    }
  }

  Shard& ShardFor(const Key& key) { return shards_[ShardIndex(key)]; }
  const Shard& ShardFor(const Key& key) const { return shards_[ShardIndex(key)]; }

  std::array<Shard, kShardCount> shards_;
  ChangeStamp stamp_;
};

}  // namespace asval
