// The test driver's entry points: the loader's layer interface, instance and device creation (the features and
// extensions it adds are reported to the layers above and taken out of what reaches the driver below), and the
// commands it executes itself. Everything else goes down the chain unchanged.
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "build_infos_below.h"
#include "chain_edits.h"
#include "deferred_operations.h"
#include "device_buffers.h"
#include "device_executor.h"
#include "device_extensions.h"
#include "driver_dispatch.h"
#include "host_commands.h"
#include "indirect_builds.h"
#include "memory_types.h"
#include "motion_blur.h"
#include "nv_ray_tracing.h"
#include "opacity_micromap.h"

#define ASVAL_DRIVER_EXPORT extern "C" __attribute__((visibility("default")))

namespace asval_test_driver {
namespace {

// The features the test driver adds to the driver below: it executes these commands itself.
void AddFeatures(void* chain) {
  for (auto* s = static_cast<VkBaseOutStructure*>(chain); s != nullptr; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR) {
      auto* as = reinterpret_cast<VkPhysicalDeviceAccelerationStructureFeaturesKHR*>(s);
      as->accelerationStructureHostCommands = VK_TRUE;
      as->accelerationStructureIndirectBuild = VK_TRUE;
    }
  }
  ReportMotionBlurFeatures(chain);
  ReportOpacityMicromapFeatures(chain);
}

// The features structures of the extensions the test driver adds, out of a chain the driver below reads (it has not
// got the extensions) while it does.
struct AddedFeaturesOutOfChain {
  explicit AddedFeaturesOutOfChain(void* head)
      : motion_blur(head, VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV),
        opacity_micromap(head, VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_FEATURES_EXT) {}
  const StructureOutOfChain motion_blur;
  const StructureOutOfChain opacity_micromap;  // put back first: the chain's links are restored in reverse order
};

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceFeatures2(VkPhysicalDevice gpu, VkPhysicalDeviceFeatures2* features) {
  InstanceData* instance = InstanceOf(gpu);
  {
    const AddedFeaturesOutOfChain added(features);
    instance->GetPhysicalDeviceFeatures2(gpu, features);
  }
  AddFeatures(features->pNext);
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceFeatures2KHR(VkPhysicalDevice gpu, VkPhysicalDeviceFeatures2* features) {
  InstanceData* instance = InstanceOf(gpu);
  {
    const AddedFeaturesOutOfChain added(features);
    (instance->GetPhysicalDeviceFeatures2KHR ? instance->GetPhysicalDeviceFeatures2KHR
                                             : instance->GetPhysicalDeviceFeatures2)(gpu, features);
  }
  AddFeatures(features->pNext);
}

// The memory the layers above see: below's types and the added device-local one (memory_types.h).
VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceMemoryProperties(VkPhysicalDevice gpu,
                                                             VkPhysicalDeviceMemoryProperties* properties) {
  InstanceOf(gpu)->GetPhysicalDeviceMemoryProperties(gpu, properties);
  AddMemoryType(properties);
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceMemoryProperties2(VkPhysicalDevice gpu,
                                                              VkPhysicalDeviceMemoryProperties2* properties) {
  InstanceData* instance = InstanceOf(gpu);
  (instance->GetPhysicalDeviceMemoryProperties2 ? instance->GetPhysicalDeviceMemoryProperties2
                                                : instance->GetPhysicalDeviceMemoryProperties2KHR)(gpu, properties);
  AddMemoryType(&properties->memoryProperties);
}

// ASVAL_TEST_DRIVER_DEVICE_TYPE=integrated-gpu: the device says it is an integrated GPU instead of lavapipe's CPU, so
// that what a layer does only on GPUs (asval's capture dispatch where it copies: docs/capture.md) runs through the
// loader too. Read when asked (a test sets it around its instance).
void ReportDeviceType(VkPhysicalDeviceProperties* properties) {
  const char* type = std::getenv("ASVAL_TEST_DRIVER_DEVICE_TYPE");
  if (type && std::strcmp(type, "integrated-gpu") == 0) {
    properties->deviceType = VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU;
  }
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceProperties(VkPhysicalDevice gpu, VkPhysicalDeviceProperties* properties) {
  InstanceOf(gpu)->GetPhysicalDeviceProperties(gpu, properties);
  ReportDeviceType(properties);
}

VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceProperties2(VkPhysicalDevice gpu, VkPhysicalDeviceProperties2* properties) {
  InstanceData* instance = InstanceOf(gpu);
  const RayTracingPropertiesNV nv(properties);
  const OpacityMicromapProperties opacity_micromap(properties);
  (instance->GetPhysicalDeviceProperties2 ? instance->GetPhysicalDeviceProperties2
                                          : instance->GetPhysicalDeviceProperties2KHR)(gpu, properties);
  ReportDeviceType(&properties->properties);
}

// The device's extensions with those the test driver adds (device_extensions.h). A layer's name goes down the chain:
// the loader answers the application's from the manifests.
VKAPI_ATTR VkResult VKAPI_CALL EnumerateDeviceExtensionProperties(VkPhysicalDevice gpu, const char* layer,
                                                                  uint32_t* count, VkExtensionProperties* properties) {
  InstanceData* instance = InstanceOf(gpu);
  if (layer != nullptr) return instance->EnumerateDeviceExtensionProperties(gpu, layer, count, properties);
  return EnumerateDeviceExtensionsWithAdded(instance->EnumerateDeviceExtensionProperties, gpu, count, properties);
}

VKAPI_ATTR VkResult VKAPI_CALL EnumeratePhysicalDevices(VkInstance handle, uint32_t* count, VkPhysicalDevice* gpus) {
  InstanceData* instance = FindInstance(handle);
  const VkResult result = instance->EnumeratePhysicalDevices(handle, count, gpus);
  if (gpus != nullptr && (result == VK_SUCCESS || result == VK_INCOMPLETE)) {
    for (uint32_t i = 0; i < *count; ++i) AddPhysicalDevice(gpus[i], instance);
  }
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateInstance(const VkInstanceCreateInfo* info, const VkAllocationCallbacks* allocator,
                                              VkInstance* out) {
  auto* link = static_cast<VkLayerInstanceCreateInfo*>(const_cast<void*>(info->pNext));
  while (link != nullptr &&
         !(link->sType == VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO && link->function == VK_LAYER_LINK_INFO)) {
    link = static_cast<VkLayerInstanceCreateInfo*>(const_cast<void*>(link->pNext));
  }
  if (link == nullptr) return VK_ERROR_INITIALIZATION_FAILED;
  const PFN_vkGetInstanceProcAddr next = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  auto create = reinterpret_cast<PFN_vkCreateInstance>(next(VK_NULL_HANDLE, "vkCreateInstance"));
  const VkResult result = create(info, allocator, out);
  if (result != VK_SUCCESS) return result;
  InstanceData* data = AddInstance(*out);
  data->next_gipa = next;
#define ASVAL_DRIVER_LOAD(name) data->name = reinterpret_cast<PFN_vk##name>(next(*out, "vk" #name))
  ASVAL_DRIVER_LOAD(DestroyInstance);
  ASVAL_DRIVER_LOAD(EnumeratePhysicalDevices);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceFeatures2);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceFeatures2KHR);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceMemoryProperties);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceMemoryProperties2);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceMemoryProperties2KHR);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceProperties);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceProperties2);
  ASVAL_DRIVER_LOAD(GetPhysicalDeviceProperties2KHR);
  ASVAL_DRIVER_LOAD(CreateDevice);
  ASVAL_DRIVER_LOAD(EnumerateDeviceExtensionProperties);
#undef ASVAL_DRIVER_LOAD
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL DestroyInstance(VkInstance handle, const VkAllocationCallbacks* allocator) {
  InstanceData* instance = FindInstance(handle);
  if (instance == nullptr) return;
  const PFN_vkDestroyInstance destroy = instance->DestroyInstance;
  RemoveInstance(handle);
  destroy(handle, allocator);
}

// The features the test driver adds, switched off in the application's chain while the driver below creates the
// device (it has not got them), then restored: the application's structures are its own.
struct HiddenFeatures {
  explicit HiddenFeatures(const void* chain) {
    for (auto* s = static_cast<const VkBaseInStructure*>(chain); s != nullptr; s = s->pNext) {
      if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR) {
        as_ = reinterpret_cast<VkPhysicalDeviceAccelerationStructureFeaturesKHR*>(const_cast<VkBaseInStructure*>(s));
        host_commands_ = as_->accelerationStructureHostCommands;
        indirect_build_ = as_->accelerationStructureIndirectBuild;
        as_->accelerationStructureHostCommands = VK_FALSE;
        as_->accelerationStructureIndirectBuild = VK_FALSE;
      }
    }
  }
  ~HiddenFeatures() {
    if (as_ == nullptr) return;
    as_->accelerationStructureHostCommands = host_commands_;
    as_->accelerationStructureIndirectBuild = indirect_build_;
  }
  HiddenFeatures(const HiddenFeatures&) = delete;
  HiddenFeatures& operator=(const HiddenFeatures&) = delete;

 private:
  VkPhysicalDeviceAccelerationStructureFeaturesKHR* as_ = nullptr;
  VkBool32 host_commands_ = VK_FALSE;
  VkBool32 indirect_build_ = VK_FALSE;
};

VKAPI_ATTR VkResult VKAPI_CALL CreateDevice(VkPhysicalDevice gpu, const VkDeviceCreateInfo* info,
                                            const VkAllocationCallbacks* allocator, VkDevice* out) {
  InstanceData* instance = InstanceOf(gpu);
  auto* link = static_cast<VkLayerDeviceCreateInfo*>(const_cast<void*>(info->pNext));
  while (link != nullptr &&
         !(link->sType == VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO && link->function == VK_LAYER_LINK_INFO)) {
    link = static_cast<VkLayerDeviceCreateInfo*>(const_cast<void*>(link->pNext));
  }
  if (instance == nullptr || link == nullptr) return VK_ERROR_INITIALIZATION_FAILED;
  const PFN_vkGetInstanceProcAddr next_gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  const PFN_vkGetDeviceProcAddr next_gdpa = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  auto create = reinterpret_cast<PFN_vkCreateDevice>(next_gipa(instance->instance, "vkCreateDevice"));
  DeviceCreateWithoutAdded create_info(*info);
  VkResult result;
  {
    const AddedFeaturesOutOfChain added(create_info.below());
    const HiddenFeatures hidden(create_info.below()->pNext);
    result = create(gpu, create_info.below(), allocator, out);
  }
  if (result != VK_SUCCESS) return result;
  DeviceData* device = AddDevice(*out);
  device->next_gdpa = next_gdpa;
#define ASVAL_DRIVER_LOAD(name) device->vk.name = reinterpret_cast<PFN_vk##name>(next_gdpa(*out, "vk" #name));
  ASVAL_DRIVER_DEVICE_FUNCTIONS(ASVAL_DRIVER_LOAD)
#undef ASVAL_DRIVER_LOAD
  instance->GetPhysicalDeviceMemoryProperties(gpu, &device->memory);
  device->queue_family = info->queueCreateInfoCount != 0 ? info->pQueueCreateInfos[0].queueFamilyIndex : 0;
  device->executor = std::make_unique<DeviceExecutor>(*device);
  device->deferred = std::make_unique<DeferredOperations>();
  device->buffers = std::make_unique<DeviceBuffers>();
  device->indirect = std::make_unique<IndirectBuilds>(*device);
  VkPhysicalDeviceMemoryProperties above = device->memory;  // the NV structures may live in any type the app sees
  AddMemoryType(&above);
  const uint32_t every_type = above.memoryTypeCount >= 32 ? ~0u : (1u << above.memoryTypeCount) - 1;
  device->nv =
      std::make_unique<NvRayTracing>(create_info.nv_enabled(), create_info.ray_tracing_pipeline_enabled(), every_type);
  device->motion_blur = create_info.motion_blur_enabled();
  device->opacity_micromap = create_info.opacity_micromap_enabled();
  device->micromaps = std::make_unique<Micromaps>();
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL DestroyDevice(VkDevice handle, const VkAllocationCallbacks* allocator) {
  DeviceData* device = FindDevice(handle);
  if (device == nullptr) return;
  device->indirect.reset();  // their pools and fence belong to the device
  device->executor.reset();
  device->hold.Destroy(*device);
  const PFN_vkDestroyDevice destroy = device->vk.DestroyDevice;
  RemoveDevice(handle);
  destroy(handle, allocator);
}

// Queues are externally synchronized: the application's submissions and waits take the lock the test driver's
// own submissions take.
// Indirect builds read their ranges when their submission reaches the test driver (indirect_builds.h).
VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue queue, uint32_t count, const VkSubmitInfo* submits, VkFence fence) {
  DeviceData* device = FindDevice(queue);
  std::vector<VkCommandBuffer> command_buffers;
  for (uint32_t i = 0; i < count; ++i) {
    command_buffers.insert(command_buffers.end(), submits[i].pCommandBuffers,
                           submits[i].pCommandBuffers + submits[i].commandBufferCount);
  }
  std::lock_guard<std::mutex> lock(device->queue_lock);
  const VkResult prepared = device->indirect->Prepare(queue, command_buffers);
  if (prepared != VK_SUCCESS) return prepared;
  return device->vk.QueueSubmit(queue, count, device->hold.Submits(count, submits), fence);
}

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue queue, uint32_t count, const VkSubmitInfo2* submits,
                                            VkFence fence) {
  DeviceData* device = FindDevice(queue);
  std::vector<VkCommandBuffer> command_buffers;
  for (uint32_t i = 0; i < count; ++i) {
    for (uint32_t c = 0; c < submits[i].commandBufferInfoCount; ++c) {
      command_buffers.push_back(submits[i].pCommandBufferInfos[c].commandBuffer);
    }
  }
  std::lock_guard<std::mutex> lock(device->queue_lock);
  const VkResult prepared = device->indirect->Prepare(queue, command_buffers);
  if (prepared != VK_SUCCESS) return prepared;
  return device->vk.QueueSubmit2(queue, count, device->hold.Submits2(count, submits), fence);
}

// Test-only (submission_hold.h).
VKAPI_ATTR VkResult VKAPI_CALL AsvalTestDriverHoldSubmissions(VkDevice handle, VkBool32 hold) {
  DeviceData* device = FindDevice(handle);
  std::lock_guard<std::mutex> lock(device->queue_lock);
  return device->hold.Hold(*device, hold == VK_TRUE);
}

VKAPI_ATTR VkResult VKAPI_CALL BeginCommandBuffer(VkCommandBuffer command_buffer,
                                                  const VkCommandBufferBeginInfo* info) {
  DeviceData* device = FindDevice(command_buffer);
  device->indirect->Begin(command_buffer);
  return device->vk.BeginCommandBuffer(command_buffer, info);
}

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructuresIndirectKHR(
    VkCommandBuffer command_buffer, uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
    const VkDeviceAddress* addresses, const uint32_t* strides, const uint32_t* const* max_counts) {
  DeviceData* device = FindDevice(command_buffer);
  const BuildInfosBelow below(*device, count, infos);  // without the added extensions' (build_infos_below.h)
  device->indirect->Record(command_buffer, count, below.get(), addresses, strides, max_counts);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateBuffer(VkDevice handle, const VkBufferCreateInfo* info,
                                            const VkAllocationCallbacks* allocator, VkBuffer* buffer) {
  DeviceData* device = FindDevice(handle);
  VkBufferCreateInfo below = *info;
  below.usage = MicromapUsageBelow(device->opacity_micromap, device->nv->UsageBelow(info->usage));
  const VkResult result = device->vk.CreateBuffer(handle, &below, allocator, buffer);
  if (result == VK_SUCCESS) device->buffers->Created(*buffer, *info);
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyBuffer(VkDevice handle, VkBuffer buffer, const VkAllocationCallbacks* allocator) {
  DeviceData* device = FindDevice(handle);
  device->buffers->Destroyed(buffer);
  device->vk.DestroyBuffer(handle, buffer, allocator);
}

VKAPI_ATTR VkResult VKAPI_CALL AllocateMemory(VkDevice handle, const VkMemoryAllocateInfo* info,
                                              const VkAllocationCallbacks* allocator, VkDeviceMemory* memory) {
  DeviceData* device = FindDevice(handle);
  VkMemoryAllocateInfo below = *info;
  below.memoryTypeIndex = MemoryTypeBelow(device->memory, info->memoryTypeIndex);
  return device->vk.AllocateMemory(handle, &below, allocator, memory);
}

VKAPI_ATTR void VKAPI_CALL GetBufferMemoryRequirements(VkDevice handle, VkBuffer buffer,
                                                       VkMemoryRequirements* requirements) {
  DeviceData* device = FindDevice(handle);
  device->vk.GetBufferMemoryRequirements(handle, buffer, requirements);
  requirements->memoryTypeBits = MemoryTypeBitsAbove(device->memory, requirements->memoryTypeBits);
}

VKAPI_ATTR void VKAPI_CALL GetBufferMemoryRequirements2(VkDevice handle, const VkBufferMemoryRequirementsInfo2* info,
                                                        VkMemoryRequirements2* requirements) {
  DeviceData* device = FindDevice(handle);
  device->vk.GetBufferMemoryRequirements2(handle, info, requirements);
  VkMemoryRequirements& r = requirements->memoryRequirements;
  r.memoryTypeBits = MemoryTypeBitsAbove(device->memory, r.memoryTypeBits);
}

VKAPI_ATTR void VKAPI_CALL GetDeviceBufferMemoryRequirements(VkDevice handle,
                                                             const VkDeviceBufferMemoryRequirements* info,
                                                             VkMemoryRequirements2* requirements) {
  DeviceData* device = FindDevice(handle);
  device->vk.GetDeviceBufferMemoryRequirements(handle, info, requirements);
  VkMemoryRequirements& r = requirements->memoryRequirements;
  r.memoryTypeBits = MemoryTypeBitsAbove(device->memory, r.memoryTypeBits);
}

void BufferBound(DeviceData* device, VkBuffer buffer) {
  if (!device->buffers->HasAddress(buffer)) return;
  VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  info.buffer = buffer;
  device->buffers->Bound(buffer, device->vk.GetBufferDeviceAddress(device->device, &info));
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory(VkDevice handle, VkBuffer buffer, VkDeviceMemory memory,
                                                VkDeviceSize offset) {
  DeviceData* device = FindDevice(handle);
  const VkResult result = device->vk.BindBufferMemory(handle, buffer, memory, offset);
  if (result == VK_SUCCESS) BufferBound(device, buffer);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory2(VkDevice handle, uint32_t count, const VkBindBufferMemoryInfo* infos) {
  DeviceData* device = FindDevice(handle);
  const VkResult result = device->vk.BindBufferMemory2(handle, count, infos);
  if (result == VK_SUCCESS) {
    for (uint32_t i = 0; i < count; ++i) BufferBound(device, infos[i].buffer);
  }
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL QueueWaitIdle(VkQueue queue) {
  DeviceData* device = FindDevice(queue);
  std::lock_guard<std::mutex> lock(device->queue_lock);
  return device->vk.QueueWaitIdle(queue);
}

VKAPI_ATTR void VKAPI_CALL GetAccelerationStructureBuildSizesKHR(
    VkDevice handle, VkAccelerationStructureBuildTypeKHR, const VkAccelerationStructureBuildGeometryInfoKHR* info,
    const uint32_t* counts, VkAccelerationStructureBuildSizesInfoKHR* sizes) {
  // Host builds run on the device: the device's sizes are theirs. Builds are built without motion and micromaps
  // (build_infos_below.h): sized so.
  DeviceData* device = FindDevice(handle);
  const BuildInfosBelow below(*device, 1, info);
  device->vk.GetAccelerationStructureBuildSizesKHR(handle, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, below.get(),
                                                   counts, sizes);
}

// A host command now, or when its deferred operation is joined. The parameters stay the application's until the
// operation completes (VK_KHR_deferred_host_operations), so the work keeps pointers to them.
VkResult RunOrDefer(DeviceData* device, VkDeferredOperationKHR operation, std::function<VkResult()> work) {
  if (operation == VK_NULL_HANDLE) return work();
  return device->deferred->Defer(operation, std::move(work));
}

VKAPI_ATTR VkResult VKAPI_CALL
BuildAccelerationStructuresKHR(VkDevice handle, VkDeferredOperationKHR operation, uint32_t count,
                               const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                               const VkAccelerationStructureBuildRangeInfoKHR* const* ranges) {
  DeviceData* device = FindDevice(handle);
  // Without the added extensions' (build_infos_below.h), and kept as long as a deferred build needs it.
  const auto below = std::make_shared<const BuildInfosBelow>(*device, count, infos);
  return RunOrDefer(device, operation, [=] { return BuildOnHost(*device, count, below->get(), ranges); });
}

VKAPI_ATTR VkResult VKAPI_CALL CopyAccelerationStructureKHR(VkDevice handle, VkDeferredOperationKHR operation,
                                                            const VkCopyAccelerationStructureInfoKHR* info) {
  DeviceData* device = FindDevice(handle);
  return RunOrDefer(device, operation, [=] { return CopyOnHost(*device, *info); });
}

VKAPI_ATTR VkResult VKAPI_CALL CopyAccelerationStructureToMemoryKHR(
    VkDevice handle, VkDeferredOperationKHR operation, const VkCopyAccelerationStructureToMemoryInfoKHR* info) {
  DeviceData* device = FindDevice(handle);
  return RunOrDefer(device, operation, [=] { return CopyToMemoryOnHost(*device, *info); });
}

VKAPI_ATTR VkResult VKAPI_CALL CopyMemoryToAccelerationStructureKHR(
    VkDevice handle, VkDeferredOperationKHR operation, const VkCopyMemoryToAccelerationStructureInfoKHR* info) {
  DeviceData* device = FindDevice(handle);
  return RunOrDefer(device, operation, [=] { return CopyFromMemoryOnHost(*device, *info); });
}

VKAPI_ATTR VkResult VKAPI_CALL WriteAccelerationStructuresPropertiesKHR(VkDevice handle, uint32_t count,
                                                                        const VkAccelerationStructureKHR* structures,
                                                                        VkQueryType type, size_t data_size, void* data,
                                                                        size_t stride) {
  DeviceData* device = FindDevice(handle);
  return WritePropertiesOnHost(*device, count, structures, type, data_size, data, stride);
}

VKAPI_ATTR VkResult VKAPI_CALL DeferredOperationJoinKHR(VkDevice handle, VkDeferredOperationKHR operation) {
  return FindDevice(handle)->deferred->Join(operation);
}

VKAPI_ATTR VkResult VKAPI_CALL GetDeferredOperationResultKHR(VkDevice handle, VkDeferredOperationKHR operation) {
  return FindDevice(handle)->deferred->Result(operation);
}

VKAPI_ATTR uint32_t VKAPI_CALL GetDeferredOperationMaxConcurrencyKHR(VkDevice, VkDeferredOperationKHR) { return 1; }

VKAPI_ATTR void VKAPI_CALL DestroyDeferredOperationKHR(VkDevice handle, VkDeferredOperationKHR operation,
                                                       const VkAllocationCallbacks* allocator) {
  DeviceData* device = FindDevice(handle);
  device->deferred->Forget(operation);
  device->vk.DestroyDeferredOperationKHR(handle, operation, allocator);
}

PFN_vkVoidFunction DeviceFunction(const char* name) {
#define ASVAL_DRIVER_HOOK(fn) \
  if (std::strcmp(name, "vk" #fn) == 0) return reinterpret_cast<PFN_vkVoidFunction>(&fn);
  ASVAL_DRIVER_HOOK(DestroyDevice)
  ASVAL_DRIVER_HOOK(QueueSubmit)
  ASVAL_DRIVER_HOOK(QueueSubmit2)
  ASVAL_DRIVER_HOOK(AsvalTestDriverHoldSubmissions)
  ASVAL_DRIVER_HOOK(QueueWaitIdle)
  ASVAL_DRIVER_HOOK(GetAccelerationStructureBuildSizesKHR)
  ASVAL_DRIVER_HOOK(BuildAccelerationStructuresKHR)
  ASVAL_DRIVER_HOOK(CopyAccelerationStructureKHR)
  ASVAL_DRIVER_HOOK(CopyAccelerationStructureToMemoryKHR)
  ASVAL_DRIVER_HOOK(CopyMemoryToAccelerationStructureKHR)
  ASVAL_DRIVER_HOOK(WriteAccelerationStructuresPropertiesKHR)
  ASVAL_DRIVER_HOOK(DeferredOperationJoinKHR)
  ASVAL_DRIVER_HOOK(GetDeferredOperationResultKHR)
  ASVAL_DRIVER_HOOK(GetDeferredOperationMaxConcurrencyKHR)
  ASVAL_DRIVER_HOOK(DestroyDeferredOperationKHR)
  ASVAL_DRIVER_HOOK(BeginCommandBuffer)
  ASVAL_DRIVER_HOOK(CmdBuildAccelerationStructuresIndirectKHR)
  ASVAL_DRIVER_HOOK(CreateBuffer)
  ASVAL_DRIVER_HOOK(DestroyBuffer)
  ASVAL_DRIVER_HOOK(BindBufferMemory)
  ASVAL_DRIVER_HOOK(BindBufferMemory2)
  ASVAL_DRIVER_HOOK(AllocateMemory)
  ASVAL_DRIVER_HOOK(GetBufferMemoryRequirements)
  ASVAL_DRIVER_HOOK(GetBufferMemoryRequirements2)
  ASVAL_DRIVER_HOOK(GetDeviceBufferMemoryRequirements)
  if (std::strcmp(name, "vkGetBufferMemoryRequirements2KHR") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&GetBufferMemoryRequirements2);
  }
  if (std::strcmp(name, "vkGetDeviceBufferMemoryRequirementsKHR") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceBufferMemoryRequirements);
  }
  if (std::strcmp(name, "vkBindBufferMemory2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&BindBufferMemory2);
  if (std::strcmp(name, "vkQueueSubmit2KHR") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&QueueSubmit2);
  return nullptr;
}

PFN_vkVoidFunction InstanceFunction(const char* name) {
  ASVAL_DRIVER_HOOK(CreateInstance)
  ASVAL_DRIVER_HOOK(DestroyInstance)
  ASVAL_DRIVER_HOOK(EnumeratePhysicalDevices)
  ASVAL_DRIVER_HOOK(GetPhysicalDeviceFeatures2)
  ASVAL_DRIVER_HOOK(GetPhysicalDeviceFeatures2KHR)
  ASVAL_DRIVER_HOOK(GetPhysicalDeviceMemoryProperties)
  ASVAL_DRIVER_HOOK(GetPhysicalDeviceMemoryProperties2)
  if (std::strcmp(name, "vkGetPhysicalDeviceMemoryProperties2KHR") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&GetPhysicalDeviceMemoryProperties2);
  }
  ASVAL_DRIVER_HOOK(GetPhysicalDeviceProperties)
  ASVAL_DRIVER_HOOK(GetPhysicalDeviceProperties2)
  if (std::strcmp(name, "vkGetPhysicalDeviceProperties2KHR") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&GetPhysicalDeviceProperties2);
  }
  ASVAL_DRIVER_HOOK(CreateDevice)
  ASVAL_DRIVER_HOOK(EnumerateDeviceExtensionProperties)
#undef ASVAL_DRIVER_HOOK
  return nullptr;
}

}  // namespace

PFN_vkVoidFunction GetDeviceProcAddr(VkDevice handle, const char* name) {
  if (std::strcmp(name, "vkGetDeviceProcAddr") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr);
  if (PFN_vkVoidFunction own = DeviceFunction(name)) return own;
  DeviceData* device = handle != VK_NULL_HANDLE ? FindDevice(handle) : nullptr;
  if (device == nullptr) return nullptr;
  // VK_NV_ray_tracing's, VK_NV_ray_tracing_motion_blur's and VK_EXT_opacity_micromap's commands only where they are
  // enabled: elsewhere the device is the driver below's.
  if (device->nv->enabled()) {
    if (PFN_vkVoidFunction nv = NvRayTracingFunction(name)) return nv;
  }
  if (device->motion_blur) {
    if (PFN_vkVoidFunction motion_blur = MotionBlurFunction(name)) return motion_blur;
  }
  if (device->opacity_micromap) {
    if (PFN_vkVoidFunction micromap = OpacityMicromapFunction(name)) return micromap;
  }
  if (device->motion_blur || device->opacity_micromap) {
    if (PFN_vkVoidFunction build = BuildInfosBelowFunction(name)) return build;
  }
  return device->next_gdpa(handle, name);
}

PFN_vkVoidFunction GetInstanceProcAddr(VkInstance handle, const char* name) {
  if (std::strcmp(name, "vkGetInstanceProcAddr") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&GetInstanceProcAddr);
  }
  if (std::strcmp(name, "vkGetDeviceProcAddr") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr);
  if (PFN_vkVoidFunction own = InstanceFunction(name)) return own;
  if (handle == VK_NULL_HANDLE) return nullptr;
  if (PFN_vkVoidFunction own = DeviceFunction(name)) return own;
  if (PFN_vkVoidFunction nv = NvRayTracingFunction(name)) return nv;  // for any device: none is named here
  if (PFN_vkVoidFunction motion_blur = MotionBlurFunction(name)) return motion_blur;  // they check their device
  if (PFN_vkVoidFunction build = BuildInfosBelowFunction(name)) return build;
  if (PFN_vkVoidFunction micromap = OpacityMicromapFunction(name)) return micromap;  // a device's own objects
  InstanceData* instance = FindInstance(handle);
  return instance != nullptr ? instance->next_gipa(handle, name) : nullptr;
}

}  // namespace asval_test_driver

ASVAL_DRIVER_EXPORT VKAPI_ATTR VkResult VKAPI_CALL
vkNegotiateLoaderLayerInterfaceVersion(VkNegotiateLayerInterface* version) {
  if (version == nullptr || version->sType != LAYER_NEGOTIATE_INTERFACE_STRUCT) return VK_ERROR_INITIALIZATION_FAILED;
  if (version->loaderLayerInterfaceVersion > 2) version->loaderLayerInterfaceVersion = 2;
  version->pfnGetInstanceProcAddr = &asval_test_driver::GetInstanceProcAddr;
  version->pfnGetDeviceProcAddr = &asval_test_driver::GetDeviceProcAddr;
  version->pfnGetPhysicalDeviceProcAddr = nullptr;
  return VK_SUCCESS;
}

ASVAL_DRIVER_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetInstanceProcAddr(VkInstance instance,
                                                                                   const char* name) {
  return asval_test_driver::GetInstanceProcAddr(instance, name);
}

ASVAL_DRIVER_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetDeviceProcAddr(VkDevice device, const char* name) {
  return asval_test_driver::GetDeviceProcAddr(device, name);
}
