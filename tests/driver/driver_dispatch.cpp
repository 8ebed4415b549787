#include "driver_dispatch.h"

#include <unordered_map>

#include "deferred_operations.h"
#include "device_buffers.h"
#include "device_executor.h"
#include "indirect_builds.h"
#include "nv_ray_tracing.h"
#include "opacity_micromap.h"

namespace asval_test_driver {
namespace {

std::mutex g_lock;
std::unordered_map<void*, std::unique_ptr<InstanceData>> g_instances;  // by dispatch key
std::unordered_map<VkPhysicalDevice, InstanceData*> g_gpus;
std::unordered_map<void*, std::unique_ptr<DeviceData>> g_devices;  // by dispatch key

}  // namespace

void* DispatchKey(const void* handle) { return *static_cast<void* const*>(handle); }

InstanceData* AddInstance(VkInstance instance) {
  std::lock_guard<std::mutex> lock(g_lock);
  auto& data = g_instances[DispatchKey(instance)];
  data = std::make_unique<InstanceData>();
  data->instance = instance;
  return data.get();
}

InstanceData* FindInstance(const void* handle) {
  std::lock_guard<std::mutex> lock(g_lock);
  const auto it = g_instances.find(DispatchKey(handle));
  return it == g_instances.end() ? nullptr : it->second.get();
}

void RemoveInstance(VkInstance instance) {
  std::lock_guard<std::mutex> lock(g_lock);
  const auto it = g_instances.find(DispatchKey(instance));
  if (it == g_instances.end()) return;
  for (auto gpu = g_gpus.begin(); gpu != g_gpus.end();) {
    gpu = gpu->second == it->second.get() ? g_gpus.erase(gpu) : std::next(gpu);
  }
  g_instances.erase(it);
}

void AddPhysicalDevice(VkPhysicalDevice gpu, InstanceData* instance) {
  std::lock_guard<std::mutex> lock(g_lock);
  g_gpus[gpu] = instance;
}

InstanceData* InstanceOf(VkPhysicalDevice gpu) {
  std::lock_guard<std::mutex> lock(g_lock);
  const auto it = g_gpus.find(gpu);
  if (it != g_gpus.end()) return it->second;
  // A physical device the application got without the test driver seeing the enumeration (a group's, say)
  // dispatches through its instance's table.
  const auto instance = g_instances.find(DispatchKey(gpu));
  return instance == g_instances.end() ? nullptr : instance->second.get();
}

DeviceData* AddDevice(VkDevice device) {
  std::lock_guard<std::mutex> lock(g_lock);
  auto& data = g_devices[DispatchKey(device)];
  data = std::make_unique<DeviceData>();
  data->device = device;
  return data.get();
}

DeviceData* FindDevice(const void* handle) {
  std::lock_guard<std::mutex> lock(g_lock);
  const auto it = g_devices.find(DispatchKey(handle));
  return it == g_devices.end() ? nullptr : it->second.get();
}

void RemoveDevice(VkDevice device) {
  std::unique_ptr<DeviceData> gone;
  {
    std::lock_guard<std::mutex> lock(g_lock);
    const auto it = g_devices.find(DispatchKey(device));
    if (it == g_devices.end()) return;
    gone = std::move(it->second);
    g_devices.erase(it);
  }
}

}  // namespace asval_test_driver
