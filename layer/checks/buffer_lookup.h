#pragma once
// Device address -> buffer questions that the address, size and aliasing rules share, and the text that
// explains a failed lookup in a message.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "buffer_holders.h"  // ForEachBufferHolding, MappedBytesAt
#include "device_state.h"

namespace asval {

// A buffer of this device whose device-address range holds all of [address, address + size) (size 0: just
// `address`) and that was created with every bit of `usage` (0: any usage). Only bound buffers are in the
// address map, so a hit is bound to memory. Clean path: one address-map lookup, plus one buffer-state lookup
// per candidate when usage is asked for. While some buffer's shadow record could not be made (the layer's
// allocation failed), an address not found is unknown: a hit naming no buffer, the skip counted.
std::optional<AddressHit> FindBufferHolding(const DeviceState& state, VkDeviceAddress address, VkDeviceSize size,
                                            VkBufferUsageFlags usage);

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
