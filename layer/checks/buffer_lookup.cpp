#include "buffer_lookup.h"

#include <fmt/format.h>

#include "vk_enum_string.h"

namespace asval {

std::optional<AddressHit> FindBufferHolding(const DeviceState& state, VkDeviceAddress address, VkDeviceSize size,
                                            VkBufferUsageFlags usage) {
  std::optional<AddressHit> hit;
  if (usage == 0) {
    hit = state.buffer_addresses.FindCovering(address, size);
  } else {
    // Runs under the address map's shared lock and takes a buffer shard's shared lock: allowed (no writer of
    // the address map holds a buffer shard's lock while it waits for the map).
    hit = state.buffer_addresses.FindCovering(address, size, [&](VkBuffer buffer) {
      const std::optional<std::shared_ptr<const BufferState>> record = state.buffers.find(buffer);
      return record && *record && ((*record)->usage & usage) == usage;
    });
  }
  // Not found while some buffer's shadow record could not be made (the layer's allocation failed:
  // failure_counters.h): the address may be that buffer's. Unknown: the caller's rule is not reported (it gets a
  // hit naming no buffer), and the skip is counted here.
  if (!hit && state.failures().buffers_incomplete.load(std::memory_order_relaxed)) {
    state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    hit = AddressHit{VK_NULL_HANDLE, address, size};
  }
  return hit;
}

bool SparseAddressBuffersExist(const DeviceState& state) {
  const auto sparse = state.buffers.snapshot([](VkBuffer, const std::shared_ptr<const BufferState>& record) {
    return record && (record->create_flags & VK_BUFFER_CREATE_SPARSE_BINDING_BIT) &&
           (record->usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT);
  });
  return !sparse.empty();
}

std::string DescribeBuffersAt(const DeviceState& state, VkDeviceAddress address) {
  AddressHits hits;
  state.buffer_addresses.FindContaining(address, hits);
  if (hits.empty()) return fmt::format("no buffer of this device contains 0x{:x}", address);
  std::string text;
  for (const AddressHit& hit : hits) {
    char usage[512];
    const std::optional<std::shared_ptr<const BufferState>> record = state.buffers.find(hit.buffer);
    string_VkBufferUsageFlags(record && *record ? (*record)->usage : 0, usage, sizeof(usage));
    text += fmt::format("{}VkBuffer 0x{:x} holds [0x{:x}, 0x{:x}) with usage {}", text.empty() ? "" : "; ",
                        reinterpret_cast<uint64_t>(hit.buffer), hit.base, hit.base + hit.size, usage);
  }
  return text;
}

}  // namespace asval
