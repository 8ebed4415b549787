// Device-level hooks that keep the shadow state: memory, buffers, acceleration structures, object names.
// Each calls down first and records only what the driver accepted.
#include <mutex>

#include "capture_usage.h"
#include "footprint_report.h"
#include "history_host.h"
#include "layer_data.h"
#include "protect_notices.h"
#include "state_tracker.h"
#include "vk_struct_chain.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR void VKAPI_CALL DestroyDevice(VkDevice device, const VkAllocationCallbacks* pAllocator) {
  if (!device) return;
  std::unique_ptr<DeviceData> data = Devices().Remove(GetDispatchKey(device));
  if (data) ReportFootprint(ComputeFootprint(data->state, data->capture_pool.get(), data->capture_tracker.get()),
                            *data->reporter, device);
  if (data && data->capture_tracker) {
    // The app waited for the device to be idle (it must, to destroy it): everything captured is read now.
    CaptureTracker::Covered all;
    all.all = true;
    ProcessCaptures(*data, all);
    data->capture_tracker.reset();
    data->capture_pool->Shutdown();  // before the device goes; recordings still holding slabs give them back later
  }
  if (data && data->capture_aliases) data->capture_aliases->Shutdown();  // the layer's buffers over app memory
  if (data) {
    {
      // Batches still waiting for a semaphore value nobody signaled (the device is idle: they never ran).
      std::lock_guard<std::recursive_mutex> lock(data->state.history.submission_order);
      data->state.history.order.NeverResolved();
    }
    ReportProtectSummary(data->state, *data->reporter, device);
    ReportHistorySummary(data->state, *data->reporter, device);
  }
  if (data) data->reporter->ForgetObjectNames(device);  // its queues' and its objects' left undestroyed
  if (data && data->dispatch.DestroyDevice) data->dispatch.DestroyDevice(device, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL SetDebugUtilsObjectNameEXT(VkDevice device,
                                                          const VkDebugUtilsObjectNameInfoEXT* pNameInfo) {
  DeviceData* data = GetDeviceData(device);
  if (!data) return VK_ERROR_INITIALIZATION_FAILED;
  if (pNameInfo) {
    data->reporter->SetObjectName(device, pNameInfo->objectType, pNameInfo->objectHandle, pNameInfo->pObjectName);
  }
  // Always passed down: when the device chain has no entry for it (VK_EXT_debug_utils is an instance
  // extension), CreateDevice filled the table from the next element's instance-level entry point.
  if (!data->dispatch.SetDebugUtilsObjectNameEXT) return VK_ERROR_EXTENSION_NOT_PRESENT;  // never handed out then
  return data->dispatch.SetDebugUtilsObjectNameEXT(device, pNameInfo);
}

VKAPI_ATTR VkResult VKAPI_CALL AllocateMemory(VkDevice device, const VkMemoryAllocateInfo* pAllocateInfo,
                                              const VkAllocationCallbacks* pAllocator, VkDeviceMemory* pMemory) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.AllocateMemory(device, pAllocateInfo, pAllocator, pMemory);
  if (result == VK_SUCCESS) RecordAllocateMemory(data->state, *pAllocateInfo, *pMemory);
  return result;
}

VKAPI_ATTR void VKAPI_CALL FreeMemory(VkDevice device, VkDeviceMemory memory, const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  if (memory) RecordFreeMemory(data->state, memory);
  // After the state forgot the memory (no alias can be made for it from here) and before the downcall: the
  // layer's buffer over it goes first (memory_aliases.h).
  if (memory && data->capture_aliases) data->capture_aliases->Forget(memory);
  data->dispatch.FreeMemory(device, memory, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateBuffer(VkDevice device, const VkBufferCreateInfo* pCreateInfo,
                                            const VkAllocationCallbacks* pAllocator, VkBuffer* pBuffer) {
  DeviceData* data = GetDeviceData(device);
  // Build inputs get TRANSFER_SRC for the capture (capture_usage.h), before the app asks for their requirements.
  VkBufferCreateInfo info = *pCreateInfo;
  if (AddsCopyUsage(data->capture_tracker != nullptr, info)) info.usage |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  const VkResult result = data->dispatch.CreateBuffer(device, &info, pAllocator, pBuffer);
  if (result == VK_SUCCESS) RecordCreateBuffer(data->state, *pCreateInfo, *pBuffer, CreatedCopyable(info));
  return result;
}

// vkGetDeviceBufferMemoryRequirements and its KHR alias: answered for the create info vkCreateBuffer would pass
// down (capture_usage.h), so that memory sized by it fits the buffer the app then creates.
VKAPI_ATTR void VKAPI_CALL GetDeviceBufferMemoryRequirements(VkDevice device,
                                                             const VkDeviceBufferMemoryRequirements* pInfo,
                                                             VkMemoryRequirements2* pMemoryRequirements) {
  DeviceData* data = GetDeviceData(device);
  if (pInfo && pInfo->pCreateInfo && AddsCopyUsage(data->capture_tracker != nullptr, *pInfo->pCreateInfo)) {
    VkBufferCreateInfo info = *pInfo->pCreateInfo;
    info.usage |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    VkDeviceBufferMemoryRequirements changed = *pInfo;
    changed.pCreateInfo = &info;
    data->dispatch.GetDeviceBufferMemoryRequirements(device, &changed, pMemoryRequirements);
    return;
  }
  data->dispatch.GetDeviceBufferMemoryRequirements(device, pInfo, pMemoryRequirements);
}

VKAPI_ATTR void VKAPI_CALL DestroyBuffer(VkDevice device, VkBuffer buffer, const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  if (buffer) RecordDestroyBuffer(data->state, buffer);
  if (buffer && data->capture_aliases) data->capture_aliases->BufferDestroyed();
  data->dispatch.DestroyBuffer(device, buffer, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory(VkDevice device, VkBuffer buffer, VkDeviceMemory memory,
                                                VkDeviceSize memoryOffset) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.BindBufferMemory(device, buffer, memory, memoryOffset);
  if (result == VK_SUCCESS) RecordBindBufferMemory(data->state, data->dispatch, device, buffer, memory, memoryOffset);
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL BindBufferMemory2(VkDevice device, uint32_t bindInfoCount,
                                                 const VkBindBufferMemoryInfo* pBindInfos) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result = data->dispatch.BindBufferMemory2(device, bindInfoCount, pBindInfos);
  if (result == VK_SUCCESS) {
    for (uint32_t i = 0; i < bindInfoCount; ++i) {
      RecordBindBufferMemory(data->state, data->dispatch, device, pBindInfos[i].buffer, pBindInfos[i].memory,
                             pBindInfos[i].memoryOffset);
    }
  }
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateAccelerationStructureKHR(VkDevice device,
                                                              const VkAccelerationStructureCreateInfoKHR* pCreateInfo,
                                                              const VkAllocationCallbacks* pAllocator,
                                                              VkAccelerationStructureKHR* pAccelerationStructure) {
  DeviceData* data = GetDeviceData(device);
  const VkResult result =
      data->dispatch.CreateAccelerationStructureKHR(device, pCreateInfo, pAllocator, pAccelerationStructure);
  if (result == VK_SUCCESS) {
    RecordCreateAccelerationStructure(data->state, data->dispatch, device, *pCreateInfo, *pAccelerationStructure);
  }
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyAccelerationStructureKHR(VkDevice device,
                                                           VkAccelerationStructureKHR accelerationStructure,
                                                           const VkAllocationCallbacks* pAllocator) {
  DeviceData* data = GetDeviceData(device);
  // Before the downcall: afterwards the handle value may be handed out again by another thread.
  if (accelerationStructure) {
    RecordDestroyAccelerationStructure(data->state, accelerationStructure);
    data->reporter->ForgetObjectName(Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, accelerationStructure));
  }
  data->dispatch.DestroyAccelerationStructureKHR(device, accelerationStructure, pAllocator);
}

}  // namespace asval::hooks
