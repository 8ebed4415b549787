#pragma once
// A device's shadow state decoded from fuzz input, built through the layer's own state tracker (so that it is a
// state the layer could reach): features and limits varied, memories, buffers with sizes, usages, flags and
// device addresses (packed, aliased, overlapping, anywhere), structures of every type on them, some of them
// destroyed or their memory freed afterwards, host mappings, query pools and command buffers. The fake driver
// answers the layer's own calls (addresses, format features, build sizes) from what the input chose.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "byte_source.h"
#include "device_state.h"
#include "vk_dispatch_table.h"

namespace asval::fuzz {

// Host memory the target owns for one input: host builds' vertex, index, AABB, instance and transform data, and
// host scratch, point only in here (the spec requires valid host pointers; the layer reads some of them).
class HostArena {
 public:
  static constexpr size_t kBytes = 64 * 1024;
  explicit HostArena(uint64_t seed);
  uint8_t* data() { return bytes_.data(); }
  size_t size() const { return bytes_.size(); }
  // A pointer to `bytes` bytes inside the arena, placed where the input says (unaligned too); bytes <= kBytes.
  uint8_t* Place(ByteSource& in, size_t bytes);

 private:
  std::vector<uint8_t> bytes_;  // exactly kBytes: a read past it is a sanitizer report
};

class SyntheticDevice {
 public:
  explicit SyntheticDevice(ByteSource& in);
  SyntheticDevice(const SyntheticDevice&) = delete;
  SyntheticDevice& operator=(const SyntheticDevice&) = delete;

  DeviceState& state() { return *state_; }
  HostArena& arena() { return arena_; }
  VkDevice device() const { return device_; }

  // Handles for the commands: live or destroyed records, handles the layer never saw, VK_NULL_HANDLE.
  VkAccelerationStructureKHR Structure(ByteSource& in) const;
  VkCommandBuffer CommandBuffer(ByteSource& in) const;
  VkQueryPool QueryPool(ByteSource& in) const;
  VkDeferredOperationKHR DeferredOperation(ByteSource& in) const;
  // A device address inside, across, just outside, before or far from a buffer's range, or anything at all.
  VkDeviceAddress DeviceAddress(ByteSource& in) const;

 private:
  struct Span {
    VkDeviceAddress base;
    VkDeviceSize size;
  };
  void DecodeLimits(ByteSource& in);
  void CreateMemories(ByteSource& in);
  void CreateBuffers(ByteSource& in);
  void CreateStructures(ByteSource& in);
  void CreatePoolsAndCommandBuffers(ByteSource& in);
  void Teardowns(ByteSource& in);
  VkDeviceAddress ChooseBufferAddress(ByteSource& in, VkDeviceSize size);
  uint64_t NextHandle() { return next_handle_ += 0x10; }

  std::unique_ptr<DeviceState> state_;
  DeviceDispatchTable dispatch_{};
  VkDevice device_;
  HostArena arena_;
  uint64_t next_handle_ = 0x1000;
  VkDeviceAddress next_packed_ = 0x100000;
  std::vector<VkDeviceMemory> memories_;
  std::vector<VkBuffer> buffers_;
  std::vector<VkAccelerationStructureKHR> structures_;
  std::vector<VkQueryPool> query_pools_;
  std::vector<VkCommandBuffer> command_buffers_;
  std::vector<Span> spans_;  // device address ranges of buffers and structures, destroyed ones too
};

}  // namespace asval::fuzz
