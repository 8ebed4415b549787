#include "buffer_holders.h"

namespace asval {

const unsigned char* MappedBytesAt(const DeviceState& state, VkDeviceAddress address, std::size_t size) {
  const unsigned char* found = nullptr;
  ForEachBufferHolding(state, address, ~uint64_t{0}, [&](const BufferState& bs) {
    if (found || bs.memory_freed || !bs.Contains(address - bs.device_address, size)) return;
    const std::optional<HostMapping> mapping = state.host_mappings.OfMemory(bs.memory);
    if (!mapping) return;
    const VkDeviceSize at = bs.memory_offset + (address - bs.device_address);
    const VkDeviceSize mapped = mapping->end - mapping->begin;
    if (at < mapping->offset || at - mapping->offset > mapped || size > mapped - (at - mapping->offset)) return;
    found = reinterpret_cast<const unsigned char*>(mapping->begin + (at - mapping->offset));
  });
  return found;
}

}  // namespace asval
