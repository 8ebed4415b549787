#pragma once
// The test driver's records of the instances and devices it sits in, and the functions of the layer or driver
// below it. Looked up by dispatch key (the loader's table pointer that every dispatchable handle starts with).
#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

#include <memory>
#include <mutex>

#include "submission_hold.h"

namespace asval_test_driver {

class DeviceExecutor;
class DeferredOperations;
class DeviceBuffers;
class IndirectBuilds;
class NvRayTracing;
class Micromaps;

struct InstanceData {
  VkInstance instance = VK_NULL_HANDLE;
  PFN_vkGetInstanceProcAddr next_gipa = nullptr;
  PFN_vkDestroyInstance DestroyInstance = nullptr;
  PFN_vkEnumeratePhysicalDevices EnumeratePhysicalDevices = nullptr;
  PFN_vkGetPhysicalDeviceFeatures2 GetPhysicalDeviceFeatures2 = nullptr;
  PFN_vkGetPhysicalDeviceFeatures2KHR GetPhysicalDeviceFeatures2KHR = nullptr;
  PFN_vkGetPhysicalDeviceMemoryProperties GetPhysicalDeviceMemoryProperties = nullptr;
  PFN_vkGetPhysicalDeviceMemoryProperties2 GetPhysicalDeviceMemoryProperties2 = nullptr;
  PFN_vkGetPhysicalDeviceMemoryProperties2KHR GetPhysicalDeviceMemoryProperties2KHR = nullptr;
  PFN_vkGetPhysicalDeviceProperties GetPhysicalDeviceProperties = nullptr;
  PFN_vkGetPhysicalDeviceProperties2 GetPhysicalDeviceProperties2 = nullptr;
  PFN_vkGetPhysicalDeviceProperties2KHR GetPhysicalDeviceProperties2KHR = nullptr;
  PFN_vkCreateDevice CreateDevice = nullptr;
  PFN_vkEnumerateDeviceExtensionProperties EnumerateDeviceExtensionProperties = nullptr;
};

// The device functions below the test driver that it calls itself.
struct DeviceFunctions {
// clang-format off
#define ASVAL_DRIVER_DEVICE_FUNCTIONS(X)                                                                  \
  X(DestroyDevice) X(GetDeviceQueue) X(QueueSubmit) X(QueueSubmit2) X(QueueWaitIdle) X(DeviceWaitIdle)   \
  X(CreateCommandPool) X(DestroyCommandPool) X(AllocateCommandBuffers) X(ResetCommandPool)               \
  X(BeginCommandBuffer) X(EndCommandBuffer) X(CreateFence) X(DestroyFence) X(WaitForFences) X(ResetFences) \
  X(CreateBuffer) X(DestroyBuffer) X(GetBufferMemoryRequirements) X(AllocateMemory) X(FreeMemory)        \
  X(BindBufferMemory) X(MapMemory) X(GetBufferDeviceAddress) X(CmdPipelineBarrier)                       \
  X(CreateQueryPool) X(DestroyQueryPool) X(GetQueryPoolResults) X(CmdResetQueryPool)                     \
  X(CmdBuildAccelerationStructuresKHR) X(GetAccelerationStructureBuildSizesKHR)                           \
  X(GetAccelerationStructureDeviceAddressKHR) X(CmdCopyAccelerationStructureKHR)                          \
  X(CmdCopyAccelerationStructureToMemoryKHR) X(CmdCopyMemoryToAccelerationStructureKHR)                   \
  X(CmdWriteAccelerationStructuresPropertiesKHR) X(DestroyDeferredOperationKHR)                          \
  X(ResetCommandBuffer) X(CmdExecuteCommands) X(CmdCopyBuffer) X(BindBufferMemory2)                  \
  X(GetBufferMemoryRequirements2) X(GetDeviceBufferMemoryRequirements) X(CreateSemaphore) X(DestroySemaphore) \
  X(SignalSemaphore) X(CreateAccelerationStructureKHR)
// clang-format on
#define ASVAL_DRIVER_DECLARE(name) PFN_vk##name name = nullptr;
  ASVAL_DRIVER_DEVICE_FUNCTIONS(ASVAL_DRIVER_DECLARE)
#undef ASVAL_DRIVER_DECLARE
};

struct DeviceData {
  VkDevice device = VK_NULL_HANDLE;
  PFN_vkGetDeviceProcAddr next_gdpa = nullptr;
  DeviceFunctions vk;
  VkPhysicalDeviceMemoryProperties memory{};  // the driver below's (without the added type: memory_types.h)
  uint32_t queue_family = 0;
  // The application's queues are the driver's: the test driver's own submissions take this lock, and so do the
  // application's (vkQueueSubmit and the waits go through the test driver), as a queue is externally synchronized.
  std::mutex queue_lock;
  std::unique_ptr<DeviceExecutor> executor;
  std::unique_ptr<DeferredOperations> deferred;
  std::unique_ptr<DeviceBuffers> buffers;
  std::unique_ptr<IndirectBuilds> indirect;
  std::unique_ptr<NvRayTracing> nv;      // VK_NV_ray_tracing's structures (nv_ray_tracing.h)
  std::unique_ptr<Micromaps> micromaps;  // the test driver's own, whichever extensions are enabled (opacity_micromap.h)
  bool motion_blur = false;              // VK_NV_ray_tracing_motion_blur enabled (motion_blur.h)
  bool opacity_micromap = false;         // VK_EXT_opacity_micromap enabled (opacity_micromap.h, build_infos_below.h)
  SubmissionHold hold;                   // under queue_lock (submission_hold.h)
};

void* DispatchKey(const void* handle);

InstanceData* AddInstance(VkInstance instance);
InstanceData* FindInstance(const void* handle);
void RemoveInstance(VkInstance instance);
void AddPhysicalDevice(VkPhysicalDevice gpu, InstanceData* instance);
InstanceData* InstanceOf(VkPhysicalDevice gpu);

DeviceData* AddDevice(VkDevice device);
DeviceData* FindDevice(const void* handle);  // a device, queue or command buffer
void RemoveDevice(VkDevice device);

}  // namespace asval_test_driver
