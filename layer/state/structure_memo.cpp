#include "structure_memo.h"

#include <optional>

namespace asval {

const AccelerationStructureState* StructureMemo::FindSlow(const DeviceState& state, VkAccelerationStructureKHR handle,
                                                          std::shared_ptr<const AccelerationStructureState>& hold) {
  std::optional<std::shared_ptr<const AccelerationStructureState>> found = state.acceleration_structures.find(handle);
  std::shared_ptr<const AccelerationStructureState> record = found ? std::move(*found) : nullptr;
  Slot& slot = slots_[SlotOf(handle)];
  if (slot.handle != VK_NULL_HANDLE && slot.call == call_) {  // handed out during this call: keep it
    hold = std::move(record);
    return hold.get();
  }
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
