#pragma once
// The device addresses of the acceleration structures alive at one point of submission order (execution-time
// capture, issue 12): a top-level build's instances are checked against the structures that were alive when the
// build was submitted (pInfos-06707), once its captured instances are read, with whether each one's storage was
// bound then (pInfos-03709). One sorted snapshot is shared by every submission until a structure is created or
// destroyed (the map's change stamp) or a structure's storage is bound, destroyed or freed, so a frame that does
// none of these costs two stamp compares.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "change_stamp.h"
#include "concurrent_map.h"
#include "objects.h"

namespace asval {

// Whether a live structure's storage is bound to memory (pInfos-03709: the buffer it was created on must be), as
// known when the snapshot was taken.
enum class StructureStorage : uint8_t { kBound, kBufferDestroyed, kMemoryFreed, kUnbound, kUnknown };

struct LiveStructureAddresses {
  std::vector<VkDeviceAddress> addresses;  // sorted, each once
  // structures[k] has addresses[k] (the record as it was when the snapshot was taken), and storage[k] says
  // whether its buffer was bound then. An address is not an identity: where several live structures have one
  // address (a structure whose buffer was destroyed, and a new one created in the same memory; two structures over
  // one allocation), structures[k] is the one a reference to it may validly name (ByPreference), and shared[k] says
  // that another one had the address too, bound as well: which of them a reference meant is then not known.
  std::vector<std::shared_ptr<const AccelerationStructureState>> structures;
  std::vector<StructureStorage> storage;
  std::vector<uint8_t> shared;
  bool all_bound = true;  // every storage[k] is kBound
  // Every live structure's address is known (the layer could ask for them all): otherwise an address not found
  // may belong to a structure whose address the layer does not know, and nothing is concluded from its absence.
  bool complete = true;
  // An open-addressing table over `addresses` (index + 1 per slot, 0 empty; at most half full): a top-level
  // build's thousands of instances each cost a hash and a probe or two, not a binary search.
  std::vector<uint32_t> slots;
  uint32_t shift = 64;

  static uint64_t Hash(VkDeviceAddress address) { return address * 0x9e3779b97f4a7c15ull; }
  void Index() {
    std::size_t size = 16;
    while (size < 2 * addresses.size()) size *= 2;
    slots.assign(size, 0);
    shift = 64;
    for (std::size_t s = size; s > 1; s >>= 1) --shift;
    for (std::size_t k = 0; k < addresses.size(); ++k) {
      std::size_t slot = Hash(addresses[k]) >> shift;
      while (slots[slot] != 0) slot = (slot + 1) & (slots.size() - 1);
      slots[slot] = static_cast<uint32_t>(k + 1);
    }
  }
  // The index of the structure with this address, or -1.
  std::ptrdiff_t Find(VkDeviceAddress address) const {
    if (slots.empty()) {  // not indexed (built by hand): the sorted addresses
      const auto it = std::lower_bound(addresses.begin(), addresses.end(), address);
      return it != addresses.end() && *it == address ? it - addresses.begin() : -1;
    }
    for (std::size_t slot = Hash(address) >> shift;; slot = (slot + 1) & (slots.size() - 1)) {
      const uint32_t k = slots[slot];
      if (k == 0) return -1;
      if (addresses[k - 1] == address) return static_cast<std::ptrdiff_t>(k - 1);
    }
  }
};

class LiveStructureAddressCache {
 public:
  using StructureMap = ConcurrentMap<VkAccelerationStructureKHR, std::shared_ptr<const AccelerationStructureState>>;

  // The snapshot for now: the cached one while neither the structures nor the binding of any structure's storage
  // changed (`storage_stamp`: DeviceState::structure_storage_changes), else a new one, each structure's storage
  // judged by storage_of(const AccelerationStructureState&) -> StructureStorage.
  // `incomplete`: some live structure has no shadow record (FailureCounters::structures_incomplete), so the
  // snapshot is never complete.
  template <typename StorageOf>
  std::shared_ptr<const LiveStructureAddresses> Get(const StructureMap& structures, StampValue storage_stamp,
                                                    StorageOf&& storage_of, bool incomplete = false) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const StampValue stamp = structures.stamp();
    if (cached_ && stamp == stamp_ && storage_stamp == storage_stamp_ && (!incomplete || !cached_->complete)) {
      return cached_;
    }
    auto fresh = std::make_shared<LiveStructureAddresses>();
    if (incomplete) fresh->complete = false;
    std::vector<Candidate> live;
    for (auto& [handle, record] : structures.snapshot()) {
      if (!record || record->address == AccelerationStructureState::Address::kUnknown) {
        fresh->complete = false;
        continue;
      }
      if (record->address != AccelerationStructureState::Address::kKnown) continue;  // it has no address
      const StructureStorage storage = storage_of(*record);
      live.push_back(Candidate{std::move(record), storage});
    }
    std::sort(live.begin(), live.end(), ByPreference);
    fresh->addresses.reserve(live.size());
    fresh->storage.reserve(live.size());
    fresh->shared.reserve(live.size());
    std::vector<std::shared_ptr<const AccelerationStructureState>> kept;
    kept.reserve(live.size());
    for (std::size_t k = 0; k < live.size(); ++k) {
      const VkDeviceAddress address = live[k].record->device_address;
      if (!fresh->addresses.empty() && fresh->addresses.back() == address) {
        // The first of this address is the preferred one: the others only make it shared.
        if (live[k].storage == StructureStorage::kBound && fresh->storage.back() == StructureStorage::kBound) {
          fresh->shared.back() = 1;
        }
        continue;
      }
      fresh->addresses.push_back(address);
      fresh->storage.push_back(live[k].storage);
      fresh->shared.push_back(0);
      fresh->all_bound &= live[k].storage == StructureStorage::kBound;
      kept.push_back(std::move(live[k].record));
    }
    fresh->structures = std::move(kept);
    fresh->Index();
    cached_ = std::move(fresh);
    stamp_ = stamp;
    storage_stamp_ = storage_stamp;
    return cached_;
  }

 private:
  struct Candidate {
    std::shared_ptr<const AccelerationStructureState> record;
    StructureStorage storage;
  };
  // Sorted by address, and among structures with one address the one a reference to it may validly name first:
  // storage bound (the others' storage is gone: a reference means the bound one), then known, then lost; a
  // bottom-level one before a generic before a top-level one (instances reference bottom-level structures); then the
  // smallest (its bytes are the ones every structure there has: overlaps judged on them are certain).
  static bool ByPreference(const Candidate& a, const Candidate& b) {
    if (a.record->device_address != b.record->device_address) {
      return a.record->device_address < b.record->device_address;
    }
    const auto storage_rank = [](StructureStorage s) {
      return s == StructureStorage::kBound ? 0 : s == StructureStorage::kUnknown ? 1 : 2;
    };
    const auto type_rank = [](VkAccelerationStructureTypeKHR t) {
      if (t == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) return 0;
      return t == VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR ? 1 : 2;
    };
    if (storage_rank(a.storage) != storage_rank(b.storage)) return storage_rank(a.storage) < storage_rank(b.storage);
    if (type_rank(a.record->type) != type_rank(b.record->type)) {
      return type_rank(a.record->type) < type_rank(b.record->type);
    }
    if (a.record->size != b.record->size) return a.record->size < b.record->size;
    return a.record->handle < b.record->handle;  // a total order: the same snapshot every time
  }

  mutable std::mutex mutex_;
  mutable std::shared_ptr<const LiveStructureAddresses> cached_;
  mutable StampValue stamp_{};
  mutable StampValue storage_stamp_{};
};

}  // namespace asval
