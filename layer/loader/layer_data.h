#pragma once
// What the layer keeps per VkInstance and per VkDevice.
#include <vulkan/vulkan.h>

#include <memory>
#include <string>
#include <vector>

#include "capture_pool.h"
#include "capture_recorder.h"
#include "capture_run_end.h"
#include "capture_tracker.h"
#include "check_context.h"
#include "device_state.h"
#include "dispatch_key.h"
#include "in_flight.h"
#include "layer_settings.h"
#include "reporter.h"
#include "vk_dispatch_table.h"

namespace asval {

struct InstanceData {
  VkInstance instance = VK_NULL_HANDLE;
  InstanceDispatchTable dispatch{};
  PFN_vkGetInstanceProcAddr next_gipa = nullptr;
  uint32_t api_version = VK_API_VERSION_1_0;
  LayerSettings settings;
  std::unique_ptr<Reporter> reporter;
};

struct DeviceData {
  VkDevice device = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  InstanceData* instance = nullptr;
  DeviceDispatchTable dispatch{};
  PFN_vkGetDeviceProcAddr next_gdpa = nullptr;
  Reporter* reporter = nullptr;  // the instance's
  DeviceState state;
  // Execution-time capture (layer/capture): null when the capture setting is off or the history is not tracked.
  // The tracker is destroyed before the pool (declaration order).
  std::shared_ptr<CapturePool> capture_pool;
  std::unique_ptr<CaptureTracker> capture_tracker;
  // The layer's buffers over the app's memory that the capture's copies read through (memory_aliases.h).
  std::unique_ptr<MemoryAliases> capture_aliases;
  // Submitted batches the device may still be running (family lifetime, in_flight.h): null when the family is off
  // or the history is not tracked (no operations are recorded).
  std::unique_ptr<InFlight> in_flight;
};

// What the capture's pre-record of a build sees.
inline CaptureContext MakeCaptureContext(DeviceData& data) {
  const LayerSettings& settings = data.instance->settings;
  return CaptureContext{data.state, data.dispatch, *data.capture_pool, *data.capture_aliases, settings.capture,
                        VkDeviceSize{settings.capture_budget_mb} << 20, data.state.capture_counters};
}

// The end of a run of build commands in cb (layer/state/capture_run.h): its captures recorded into cb now
// (capture_run_end.h), before the command that ends it goes down. One load while no command buffer of the device
// holds an open run.
inline void EndCaptureRun(DeviceData& data, VkCommandBuffer cb) {
  if (!data.capture_tracker || !data.state.command_buffers.AnyOpenCaptureRun()) return;
  if (const std::shared_ptr<CommandBufferState> recording = data.state.command_buffers.Find(cb)) {
    RecordCaptureRun(MakeCaptureContext(data), cb, *recording);
  }
}

// Processes the submissions with captures that completed (or that `covered` names: the app's wait saw them
// complete): their activity is filled and the update rules judged on it (capture_hooks.cpp).
void ProcessCaptures(DeviceData& data, const CaptureTracker::Covered& covered);

// What the validate functions of a hook see: the device's shadow state (const), the reporter, the families on.
inline CheckContext MakeCheckContext(const DeviceData& data) {
  return CheckContext{data.state, *data.reporter, data.instance->settings.enabled_checks};
}

// Inline, so that each hook tests the registry's initialization guard itself instead of calling a function
// (one registry each: an inline function's static is shared by every translation unit).
inline DispatchRegistry<InstanceData>& Instances() {
  static DispatchRegistry<InstanceData> registry;
  return registry;
}
inline DispatchRegistry<DeviceData>& Devices() {
  static DispatchRegistry<DeviceData> registry;
  return registry;
}

template <typename Handle>
InstanceData* GetInstanceData(Handle handle) {
  return Instances().Find(GetDispatchKey(handle));
}
template <typename Handle>
DeviceData* GetDeviceData(Handle handle) {
  return Devices().Find(GetDispatchKey(handle));
}

}  // namespace asval
