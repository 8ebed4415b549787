#pragma once
// Device address -> buffer questions that the address, size and aliasing rules share, and the text that
// explains a failed lookup in a message.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "device_state.h"

namespace asval {

// A buffer of this device whose device-address range holds all of [address, address + size) (size 0: just
// `address`) and that was created with every bit of `usage` (0: any usage). Only bound buffers are in the
// address map, so a hit is bound to memory. Clean path: one address-map lookup, plus one buffer-state lookup
// per candidate when usage is asked for. While some buffer's shadow record could not be made (the layer's
// allocation failed), an address not found is unknown: a hit naming no buffer, the skip counted.
std::optional<AddressHit> FindBufferHolding(const DeviceState& state, VkDeviceAddress address, VkDeviceSize size,
                                            VkBufferUsageFlags usage);

// Calls hold(const BufferState&) for every live buffer bound before the id `bound_by` (BufferState::bound_serial <=
// bound_by) whose device-address range holds `address`: the buffers a command recorded or submitted at that id may
// have meant. The shared question of the lifetime rules (a destroy at submission, a recording judged at submission).
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

// End of [address, address + size), saturated at 2^64 - 1 (a range that wraps is held by no buffer anyway).
inline VkDeviceSize SaturatingAdd(VkDeviceSize a, VkDeviceSize b) { return a + b < a ? ~VkDeviceSize{0} : a + b; }
inline VkDeviceSize SaturatingMul(VkDeviceSize a, VkDeviceSize b) {
  VkDeviceSize product = 0;
  return __builtin_mul_overflow(a, b, &product) ? ~VkDeviceSize{0} : product;
}

// True when a live sparse buffer could hold device addresses the layer cannot see (sparse buffers are never
// bound with vkBindBufferMemory, so their ranges are not in the address map). A lookup that found nothing is
// then not a finding: the caller counts it as unknown state. Scans every buffer: call only when reporting.
bool SparseAddressBuffersExist(const DeviceState& state);

// "buffer 0x.. [0x.., 0x..) with usage ..., buffer ..." for every buffer that contains `address`, or "no buffer
// of this device contains 0x..". For messages only.
std::string DescribeBuffersAt(const DeviceState& state, VkDeviceAddress address);

}  // namespace asval
