#pragma once
// The shadow state of one VkDevice: what was enabled and queried at creation (immutable afterwards) and the
// live objects the acceleration-structure rules need, in sharded maps that any thread may read.
#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "address_map.h"
#include "build_size_cache.h"
#include "command_buffers.h"
#include "concurrent_map.h"
#include "failure_injection.h"
#include "format_features.h"
#include "history_state.h"
#include "host_mappings.h"
#include "live_structure_addresses.h"
#include "object_lifetimes.h"
#include "objects.h"
#include "protect_marks.h"
#include "ray_bindings.h"

namespace asval {

struct DeviceFeatures {
  bool acceleration_structure = false;
  bool acceleration_structure_host_commands = false;
  bool acceleration_structure_indirect_build = false;
  bool acceleration_structure_capture_replay = false;
  bool buffer_device_address = false;
  bool ray_query = false;
  bool ray_tracing_pipeline = false;
  bool nv_ray_tracing = false;  // the device extension VK_NV_ray_tracing is enabled
  // Not a feature, but read from the same create-info chain: VkDeviceGroupDeviceCreateInfo::physicalDeviceCount.
  uint32_t physical_device_count = 1;
};

struct DeviceProperties {
  VkPhysicalDeviceProperties core{};
  VkPhysicalDeviceAccelerationStructurePropertiesKHR acceleration_structure{};
  // Asked only where VK_NV_ray_tracing is enabled (zero otherwise: maxGeometryCount 0 means unknown).
  VkPhysicalDeviceRayTracingPropertiesNV ray_tracing_nv{};
  VkPhysicalDeviceMemoryProperties memory{};
  // VkPhysicalDeviceMaintenance4Properties::maxBufferSize where the instance and the device are 1.3; else 2^30, the
  // least any implementation allows.
  VkDeviceSize max_buffer_size = VkDeviceSize{1} << 30;
  // The queue families the device has queues of (its VkDeviceQueueCreateInfos), each once.
  std::vector<uint32_t> queue_families;
};

class DeviceState {
 public:
  // A device is being created: the test hook ASVAL_TEST_FAIL is read now (failure_injection.h).
  DeviceState() {
    ArmFailureInjectionFromEnvironment();
    command_buffers.SetFailureCounters(&capture_counters.failures);
  }

  // Set once while vkCreateDevice runs, before any other thread can see the device.
  DeviceFeatures features;
  DeviceProperties properties;
  // The settings enable a family that needs the build history (history, or copies for dst-03561): operations
  // are recorded and applied only then.
  bool history_tracked = true;
  // Family lifetime is on: device builds keep the addresses they read and write (OpBatch::touches), which the
  // in-flight checks look up when an object is destroyed (layer/checks/lifetime.h).
  bool lifetime_tracked = true;
  // Family traces or lifetime is on: the structures that trace and ray-query work binds are followed (ray_bindings.h):
  // traces judges each trace or dispatch reading them at submission (layer/checks/traced_structures.h), lifetime
  // holds them in use while it is pending (layer/checks/lifetime.h).
  bool traces_tracked = true;
  // With capture = all, degenerate instances (the degenerate_instance capture warning, info severity) or instance
  // translations (the float_spacing capture warning) are judged: each captured top-level build keeps the activity
  // of every live structure as of its submission.
  bool instance_activity_snapshots = false;

  ConcurrentMap<VkDeviceMemory, std::shared_ptr<const MemoryState>> memories;
  ConcurrentMap<VkBuffer, std::shared_ptr<const BufferState>> buffers;
  ConcurrentMap<VkAccelerationStructureKHR, std::shared_ptr<const AccelerationStructureState>> acceleration_structures;
  ConcurrentMap<VkAccelerationStructureNV, std::shared_ptr<const NvStructureState>> nv_structures;
  // Device addresses of buffers created with SHADER_DEVICE_ADDRESS usage, once bound.
  DeviceAddressMap buffer_addresses;

  // Build history in execution order: command-buffer operation logs, histories, query pools (issue 6).
  HistoryState history;
  // vkGetAccelerationStructureBuildSizesKHR answers by build signature (the size and aliasing rules).
  BuildSizeCache build_sizes;
  // Host pointers from vkMapMemory (host builds' scratch must fit in what the app mapped).
  HostMappings host_mappings;
  // Command pools and buffers: level, protected-ness (commandBuffer-09547), recorded operations.
  CommandBufferMap command_buffers;
  // Buffer format features, asked of the driver once per format (vertexFormat-03797).
  FormatFeatureCache format_features;

  // The device addresses of the live structures, as a top-level build submitted now must see them (capture).
  LiveStructureAddressCache live_structure_addresses;
  // Bumped when a buffer with ACCELERATION_STRUCTURE_STORAGE usage is bound, destroyed or has its memory freed: a
  // structure's storage may have changed (the snapshot above is taken again).
  ChangeStamp structure_storage_changes;
  // Structures whose address the layer will ask for when their buffer is bound (Address::kAwaitingBind): while
  // there are none, binding a storage buffer looks for nothing.
  std::atomic<uint32_t> structures_awaiting_address{0};
  // Execution-time capture (layer/capture): what it captured, and could not; and the layer's own failures
  // (capture_counters.failures: failure_counters.h).
  mutable CaptureCounters capture_counters;
  FailureCounters& failures() const { return capture_counters.failures; }
  // Checks skipped because the state they need is unknown (a limit the driver did not report, an object the
  // layer never saw): counted, never guessed. Shown in summaries.
  mutable std::atomic<uint64_t> checks_skipped_unknown_state{0};
  // Family lifetime (layer/checks/lifetime.h): destroys and frees judged against the work in flight, and why some of
  // that work could not be judged.
  struct LifetimeCounters {
    std::atomic<uint64_t> calls_judged{0};      // destroys and frees of an object some work in flight may use
    std::atomic<uint64_t> kept_back{0};         // destroys the layer made later (skipped by the app or protect mode)
    std::atomic<uint64_t> skipped_no_fence{0};  // batches with no fence to ask
    std::atomic<uint64_t> skipped_host_may_know{0};  // batches the host may know complete before their fence
    // At submission (layer/checks/recorded_objects.h): recorded objects found destroyed since the recording, and
    // those whose destruction the layer no longer remembers (ObjectLifetimes' ring passed them).
    std::atomic<uint64_t> recorded_judged{0};
    std::atomic<uint64_t> skipped_recorded_forgotten{0};
  };
  mutable LifetimeCounters lifetime_counters;
  // Family traces: the structures judged at submission, and why others were not (TracedSkip order).
  struct TraceCounters {
    std::atomic<uint64_t> judged{0};
    std::array<std::atomic<uint64_t>, 8> skipped{};
  };
  mutable TraceCounters trace_counters;
  // Shader modules, pipelines, layouts, templates and descriptor sets that hold acceleration structures.
  RayBindings ray_bindings;
  // When structures were created and structures and buffers destroyed (family lifetime): a command recorded before
  // is judged at submission.
  ObjectLifetimes lifetimes;
  // Calls protect mode kept from the driver, and whether an error judged at completion halted submissions
  // (protect_marks.h).
  ProtectCounters protect_counters;
  SubmissionHalt protect_halt;

  // A fresh id, unique on this device (BufferState::id).
  uint64_t NextObjectId() { return next_object_id_.fetch_add(1, std::memory_order_relaxed) + 1; }
  // The newest id given so far: an object created, bound or destroyed after this read gets a larger one. A command
  // records it (OpOrigin::recorded_at) without taking an id (a load, not a read-modify-write, per recorded command).
  uint64_t LastObjectId() const { return next_object_id_.load(std::memory_order_relaxed); }

 private:
  std::atomic<uint64_t> next_object_id_{0};
};

}  // namespace asval
