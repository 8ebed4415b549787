#include "structure_memo.h"

#include <optional>

namespace asval {

const AccelerationStructureState* StructureMemo::FindSlow(const DeviceState& state, VkAccelerationStructureKHR handle,
                                                          std::shared_ptr<const AccelerationStructureState>& hold) {
  std::optional<std::shared_ptr<const AccelerationStructureState>> found = state.acceleration_structures.find(handle);
  std::shared_ptr<const AccelerationStructureState> record = found ? std::move(*found) : nullptr;
  // The slot to replace: an empty one, else one not handed out during this call (the one used longest ago).
  Slot& first = slots_[SlotOf(handle)];
  Slot& second = slots_[SlotOf(handle) ^ 1];
  const auto free_now = [&](const Slot& s) { return s.handle == VK_NULL_HANDLE || s.call != call_; };
  Slot* victim = nullptr;
  if (first.handle == VK_NULL_HANDLE) {
    victim = &first;
  } else if (second.handle == VK_NULL_HANDLE) {
    victim = &second;
  } else if (free_now(first) && (!free_now(second) || first.call <= second.call)) {
    victim = &first;
  } else if (free_now(second)) {
    victim = &second;
  }
  if (!victim) {  // both handed out during this call: keep them
    hold = std::move(record);
    return hold.get();
  }
  Slot& slot = *victim;
  slot.handle = handle;
  slot.record = std::move(record);
  slot.call = call_;
  return slot.record.get();
}

void StructureMemo::Reset() {
  for (Slot& slot : slots_) {
    slot.handle = VK_NULL_HANDLE;
    slot.record.reset();
  }
}

}  // namespace asval
