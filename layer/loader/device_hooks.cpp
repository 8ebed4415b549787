// Device-level hooks that keep the shadow state: memory, buffers, acceleration structures, object names.
// Each calls down first and records only what the driver accepted.
#include <functional>
#include <mutex>
#include <new>

#include "capture_usage.h"
#include "footprint_report.h"
#include "history_host.h"
#include "layer_data.h"
#include "lifetime.h"
#include "protect_notices.h"
#include "protect_scope.h"
#include "state_tracker.h"
#include "traced_structures.h"
#include "vk_struct_chain.h"
#include "vk_intercepts.h"

namespace asval::hooks {

namespace {

// A destroy or free that the app's callback or protect mode kept from the driver while the device still uses the
// object (family lifetime, lifetime.h): made once the work submitted before it completed (in_flight.h), so that
// nothing leaks. Should that not fit in memory, it goes down now, as the app asked.
void DeferDestroy(DeviceData& data, std::function<void()> destroy, VkBuffer buffer = VK_NULL_HANDLE,
                  VkDeviceMemory memory = VK_NULL_HANDLE) {
  try {
    data.in_flight->Defer(data.state.NextObjectId(), destroy, buffer, memory);
    data.state.lifetime_counters.kept_back.fetch_add(1, std::memory_order_relaxed);
  } catch (const std::bad_alloc&) {
    data.state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
    destroy();
  }
}

}  // namespace

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
    // The device is idle: destroys the layer kept back run now (before the capture's alias buffers go), and the
    // in-flight fences go (after the tracker polled them).
    data->in_flight.reset();
    data->capture_tracker.reset();
    data->capture_pool->Shutdown();  // before the device goes; recordings still holding slabs give them back later
  }
  if (data && data->in_flight) data->in_flight.reset();  // without the capture: the same, now
  if (data && data->capture_aliases) data->capture_aliases->Shutdown();  // the layer's buffers over app memory
  if (data) {
    {
      // Batches still waiting for a semaphore value nobody signaled (the device is idle: they never ran).
      std::lock_guard<std::recursive_mutex> lock(data->state.history.submission_order);
      data->state.history.order.NeverResolved();
    }
    ReportProtectSummary(data->state, *data->reporter, device);
    ReportHistorySummary(data->state, *data->reporter, device);
    ReportLifetimeSummary(data->state, *data->reporter, device);
    ReportTracesSummary(data->state, *data->reporter, device);
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
  if (memory && data->in_flight) {
    const ProtectScope protect(data->reporter->protects());
    if (CheckFreeMemoryInUse(MakeCheckContext(*data), *data->in_flight, memory)) {
      if (protect.withheld()) ReportDeferredDestroy(MakeCheckContext(*data), "vkFreeMemory", device, protect);
      // Kept from the driver until the work using it completed; the app's view of the memory ends now.
      // The capture's alias buffer over it goes with it (the work may still copy through it).
      RecordFreeMemory(data->state, memory);
      DeferDestroy(*data, [data, device, memory, pAllocator] {
        if (data->capture_aliases) data->capture_aliases->Forget(memory);
        data->dispatch.FreeMemory(device, memory, pAllocator);
      });
      return;
    }
  }
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
  if (buffer && data->in_flight) {
    const ProtectScope protect(data->reporter->protects());
    if (CheckDestroyBufferInUse(MakeCheckContext(*data), *data->in_flight, buffer)) {
      if (protect.withheld()) ReportDeferredDestroy(MakeCheckContext(*data), "vkDestroyBuffer", device, protect);
      std::optional<std::shared_ptr<const BufferState>> record = data->state.buffers.find(buffer);
      const VkDeviceMemory memory = record && *record ? (*record)->memory : VK_NULL_HANDLE;
      RecordDestroyBuffer(data->state, buffer);
      if (data->capture_aliases) data->capture_aliases->BufferDestroyed();
      DeferDestroy(
          *data, [data, device, buffer, pAllocator] { data->dispatch.DestroyBuffer(device, buffer, pAllocator); },
          buffer, memory);
      return;
    }
  }
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
  bool defer = false;
  if (accelerationStructure && data->in_flight) {
    const ProtectScope protect(data->reporter->protects());
    defer = CheckDestroyStructureInUse(MakeCheckContext(*data), *data->in_flight, accelerationStructure);
    if (defer && protect.withheld()) {
      ReportDeferredDestroy(MakeCheckContext(*data), "vkDestroyAccelerationStructureKHR", device, protect);
    }
  }
  // Before the downcall: afterwards the handle value may be handed out again by another thread.
  if (accelerationStructure) {
    RecordDestroyAccelerationStructure(data->state, accelerationStructure);
    data->reporter->ForgetObjectName(Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, accelerationStructure));
  }
  if (defer) {
    return DeferDestroy(*data, [data, device, accelerationStructure, pAllocator] {
      data->dispatch.DestroyAccelerationStructureKHR(device, accelerationStructure, pAllocator);
    });
  }
  data->dispatch.DestroyAccelerationStructureKHR(device, accelerationStructure, pAllocator);
}

}  // namespace asval::hooks
