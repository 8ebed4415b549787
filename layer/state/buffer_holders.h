#pragma once
// Device address -> the buffers that hold it, and -> the app's host pointer to the bytes there: state queries that
// rule families (layer/checks) and the state's own bookkeeping at submission (traced_tops.h) share.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>

#include "device_state.h"

namespace asval {

// Calls hold(const BufferState&) for every live buffer bound before the id `bound_by` (BufferState::bound_serial <=
// bound_by) whose device-address range holds `address`: the buffers a command recorded or submitted at that id may
// have meant.
template <typename Hold>
void ForEachBufferHolding(const DeviceState& state, VkDeviceAddress address, uint64_t bound_by, Hold&& hold) {
  AddressHits hits;
  state.buffer_addresses.FindContaining(address, hits);
  for (const AddressHit& hit : hits) {
    const std::optional<std::shared_ptr<const BufferState>> b = state.buffers.find(hit.buffer);
    if (b && *b && (*b)->bound && (*b)->bound_serial <= bound_by) hold(**b);
  }
}

// The app's host pointer to the `size` bytes at a device address, where the app has mapped the memory under a live
// buffer holding all of them; null otherwise (what the device reads there is then not known to the host).
const unsigned char* MappedBytesAt(const DeviceState& state, VkDeviceAddress address, std::size_t size);

}  // namespace asval
