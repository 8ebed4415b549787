#pragma once
// The acceleration-structure records recent build commands have looked up (destinations and sources): a frame
// builds the same structures call after call, and each lookup in the shared map costs a shard's lock and a
// hash. One memo per thread, kept from call to call: Sync, at the start of each call, empties it unless the
// device's structure map is the very one it was filled from and has not changed since (its change stamp), so it
// never serves a stale record. The memo holds each record it hands out (a shared_ptr), so a record stays valid
// until the next Sync even if another thread destroys the structure meanwhile; a lookup whose slot already
// holds another record handed out during this call gives the record to the caller to hold instead.
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <memory>

#include "device_state.h"

namespace asval {

class StructureMemo {
 public:
  // Empties the memo unless it was filled from this very map, unchanged since. Call before any lookup of a
  // command.
  void Sync(const DeviceState& state) {
    ++call_;
    const StampValue stamp = state.acceleration_structures.stamp();
    if (stamp == stamp_) return;
    stamp_ = stamp;
    Reset();
  }
  // The record of `handle`; null when it is VK_NULL_HANDLE or not a live structure of this device. Valid until
  // the next Sync: held by the memo, or, when the memo is full, by `hold`.
  const AccelerationStructureState* Find(const DeviceState& state, VkAccelerationStructureKHR handle,
                                         std::shared_ptr<const AccelerationStructureState>& hold) {
    if (handle == VK_NULL_HANDLE) return nullptr;
    const unsigned k = SlotOf(handle);
    Slot* slot = &slots_[k];
    if (slot->handle != handle) {
      slot = &slots_[k ^ 1];
      if (slot->handle != handle) return FindSlow(state, handle, hold);
    }
    slot->call = call_;
    return slot->record.get();
  }

 private:
  // Two-way: a handle lives in slot SlotOf(handle) or its partner (the index with the last bit flipped), so that
  // a few structures whose handles share a slot (a 16-info command's destinations in 128 direct-mapped slots
  // collide about one time in three) do not go to the map on every call. A slot that handed out its record
  // during this call is not replaced (the caller may still use it): when both have, the lookup goes to the map
  // and its caller holds the record.
  static constexpr unsigned kSlots = 128;
  struct Slot {
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    std::shared_ptr<const AccelerationStructureState> record;  // null: not a live structure (also memoized)
    uint64_t call = 0;  // the call that last handed it out
  };
  static unsigned SlotOf(VkAccelerationStructureKHR handle) {
    return static_cast<unsigned>((reinterpret_cast<uint64_t>(handle) * 0x9e3779b97f4a7c15ull) >> 57);
  }
  const AccelerationStructureState* FindSlow(const DeviceState& state, VkAccelerationStructureKHR handle,
                                             std::shared_ptr<const AccelerationStructureState>& hold);
  void Reset();

  std::array<Slot, kSlots> slots_{};
  StampValue stamp_;  // the map the slots come from, as it was (id 0: none yet)
  uint64_t call_ = 0;  // counts Syncs: one per command
};

}  // namespace asval
