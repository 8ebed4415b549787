#pragma once
// The shadow state of one VkDevice: what was enabled and queried at creation (immutable afterwards) and the
// live objects the acceleration-structure rules need, in sharded maps that any thread may read.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <memory>

#include "address_map.h"
#include "concurrent_map.h"
#include "objects.h"

namespace asval {

struct DeviceFeatures {
  bool acceleration_structure = false;
  bool acceleration_structure_host_commands = false;
  bool acceleration_structure_indirect_build = false;
  bool acceleration_structure_capture_replay = false;
  bool buffer_device_address = false;
  bool ray_query = false;
  bool ray_tracing_pipeline = false;
};

struct DeviceProperties {
  VkPhysicalDeviceProperties core{};
  VkPhysicalDeviceAccelerationStructurePropertiesKHR acceleration_structure{};
  VkPhysicalDeviceMemoryProperties memory{};
};

class DeviceState {
 public:
  // Set once while vkCreateDevice runs, before any other thread can see the device.
  DeviceFeatures features;
  DeviceProperties properties;

  ConcurrentMap<VkDeviceMemory, std::shared_ptr<const MemoryState>> memories;
  ConcurrentMap<VkBuffer, std::shared_ptr<const BufferState>> buffers;
  ConcurrentMap<VkAccelerationStructureKHR, std::shared_ptr<const AccelerationStructureState>> acceleration_structures;
  // Device addresses of buffers created with SHADER_DEVICE_ADDRESS usage, once bound.
  DeviceAddressMap buffer_addresses;

  // Checks skipped because the state they need is unknown (a limit the driver did not report, an object the
  // layer never saw): counted, never guessed. Shown in summaries.
  mutable std::atomic<uint64_t> checks_skipped_unknown_state{0};
};

}  // namespace asval
