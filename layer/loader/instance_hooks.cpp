// Instance-level hooks: chaining vkCreateInstance/vkCreateDevice as the loader documents, settings, the
// reporter, and the app's debug messengers.
#include <vulkan/vk_layer.h>

#include <algorithm>
#include <cstring>

#include "layer_data.h"
#include "layer_info.h"
#include "state_tracker.h"
#include "vk_intercepts.h"
#include "vk_struct_chain.h"

namespace asval {

namespace {

// The loader's link info for the next element of the chain (LoaderLayerInterface.md, "Layer Dispatch
// Initialization"). The chain lives in the create info, which is const for us but is advanced in place, as
// every layer does.
template <typename LinkInfo, typename CreateInfo>
LinkInfo* FindLinkInfo(const CreateInfo* create_info, VkStructureType link_type) {
  for (auto* s = static_cast<const VkBaseInStructure*>(create_info->pNext); s; s = s->pNext) {
    if (s->sType != link_type) continue;
    auto* info = reinterpret_cast<LinkInfo*>(const_cast<VkBaseInStructure*>(s));
    if (info->function == VK_LAYER_LINK_INFO) return info;
  }
  return nullptr;
}

ReportSettings ToReportSettings(const LayerSettings& s) {
  ReportSettings r;
  r.report_errors = (s.report_flags & kSeverityError) != 0;
  r.report_warnings = (s.report_flags & kSeverityWarn) != 0;
  r.report_info = (s.report_flags & kSeverityInfo) != 0;
  r.duplicate_message_limit = s.duplicate_message_limit;
  r.message_id_filter = s.message_id_filter;
  r.report_file = s.report_file;
  r.log_to_stderr = s.log_to_stderr;
  r.protect = s.protect;
  return r;
}

void QueryDeviceProperties(const InstanceData& instance, VkPhysicalDevice gpu, bool nv_ray_tracing,
                           DeviceProperties* out) {
  const InstanceDispatchTable& d = instance.dispatch;
  if (d.GetPhysicalDeviceMemoryProperties) d.GetPhysicalDeviceMemoryProperties(gpu, &out->memory);
  out->acceleration_structure.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
  if (d.GetPhysicalDeviceProperties2) {
    VkPhysicalDeviceProperties2 props2{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &out->acceleration_structure, {}};
    d.GetPhysicalDeviceProperties2(gpu, &props2);
    out->core = props2.properties;
  } else if (d.GetPhysicalDeviceProperties) {
    // No properties2 (a 1.0 instance without VK_KHR_get_physical_device_properties2): the AS limits stay
    // zero and the checks that need them count themselves as skipped.
    d.GetPhysicalDeviceProperties(gpu, &out->core);
  }
  out->acceleration_structure.pNext = nullptr;
  // The largest buffer (the capture's buffers over the app's memory, memory_aliases.h): a 1.3 structure, asked
  // for only where both the instance and the device are 1.3.
  if (d.GetPhysicalDeviceProperties2 && instance.api_version >= VK_API_VERSION_1_3 &&
      out->core.apiVersion >= VK_API_VERSION_1_3) {
    VkPhysicalDeviceMaintenance4Properties maintenance4{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &maintenance4, {}};
    d.GetPhysicalDeviceProperties2(gpu, &props2);
    if (maintenance4.maxBufferSize != 0) out->max_buffer_size = maintenance4.maxBufferSize;
  }
  // VK_NV_ray_tracing's limits (maxGeometryCount: vkCmdBuildAccelerationStructureNV-geometryCount-02241), asked only
  // where the app enabled it: a driver without it need not know the structure.
  if (nv_ray_tracing && d.GetPhysicalDeviceProperties2) {
    out->ray_tracing_nv.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PROPERTIES_NV;
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &out->ray_tracing_nv, {}};
    d.GetPhysicalDeviceProperties2(gpu, &props2);
    out->ray_tracing_nv.pNext = nullptr;
  }
}

// The queue families the device is created with queues of, each once.
std::vector<uint32_t> QueueFamilies(const VkDeviceCreateInfo& info) {
  std::vector<uint32_t> families;
  for (uint32_t k = 0; info.pQueueCreateInfos && k < info.queueCreateInfoCount; ++k) {
    const uint32_t family = info.pQueueCreateInfos[k].queueFamilyIndex;
    if (std::find(families.begin(), families.end(), family) == families.end()) families.push_back(family);
  }
  return families;
}

// Whether the app enabled a device extension.
bool EnablesExtension(const VkDeviceCreateInfo& info, const char* name) {
  for (uint32_t k = 0; k < info.enabledExtensionCount; ++k) {
    if (info.ppEnabledExtensionNames[k] && std::strcmp(info.ppEnabledExtensionNames[k], name) == 0) return true;
  }
  return false;
}

}  // namespace

namespace hooks {

VKAPI_ATTR VkResult VKAPI_CALL CreateInstance(const VkInstanceCreateInfo* pCreateInfo,
                                              const VkAllocationCallbacks* pAllocator, VkInstance* pInstance) {
  auto* link = FindLinkInfo<VkLayerInstanceCreateInfo>(pCreateInfo, VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO);
  if (!link || !link->u.pLayerInfo) return VK_ERROR_INITIALIZATION_FAILED;
  PFN_vkGetInstanceProcAddr next_gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  auto next_create = reinterpret_cast<PFN_vkCreateInstance>(next_gipa(VK_NULL_HANDLE, "vkCreateInstance"));
  if (!next_create) return VK_ERROR_INITIALIZATION_FAILED;

  // Settings and reporter first, so that the app's create-time messengers hear about bad settings.
  auto data = std::make_unique<InstanceData>();
  std::vector<std::string> warnings;
  data->settings = LoadLayerSettings(pCreateInfo->pNext, &warnings);
  data->reporter = std::make_unique<Reporter>(ToReportSettings(data->settings));
  for (auto* s = static_cast<const VkBaseInStructure*>(pCreateInfo->pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT) {
      data->reporter->AddMessenger(VK_NULL_HANDLE, *reinterpret_cast<const VkDebugUtilsMessengerCreateInfoEXT*>(s));
    }
  }
  for (const std::string& w : warnings) {
    data->reporter->Report(Severity::kWarning, "ASVAL-Settings-Invalid", Location("vkCreateInstance"), {}, w);
  }

  link->u.pLayerInfo = link->u.pLayerInfo->pNext;  // the next layer reads its own link
  const VkResult result = next_create(pCreateInfo, pAllocator, pInstance);
  if (result != VK_SUCCESS) return result;

  data->instance = *pInstance;
  data->next_gipa = next_gipa;
  data->api_version = pCreateInfo->pApplicationInfo && pCreateInfo->pApplicationInfo->apiVersion
                          ? pCreateInfo->pApplicationInfo->apiVersion
                          : VK_API_VERSION_1_0;
  InitInstanceDispatchTable(*pInstance, next_gipa, &data->dispatch);
  data->reporter->RemoveCreateTimeMessengers();
  Instances().Insert(GetDispatchKey(*pInstance), std::move(data));
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL DestroyInstance(VkInstance instance, const VkAllocationCallbacks* pAllocator) {
  if (!instance) return;
  std::unique_ptr<InstanceData> data = Instances().Remove(GetDispatchKey(instance));
  if (data && data->dispatch.DestroyInstance) data->dispatch.DestroyInstance(instance, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDevice(VkPhysicalDevice physicalDevice, const VkDeviceCreateInfo* pCreateInfo,
                                            const VkAllocationCallbacks* pAllocator, VkDevice* pDevice) {
  InstanceData* instance = GetInstanceData(physicalDevice);
  auto* link = FindLinkInfo<VkLayerDeviceCreateInfo>(pCreateInfo, VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO);
  if (!instance || !link || !link->u.pLayerInfo) return VK_ERROR_INITIALIZATION_FAILED;
  PFN_vkGetInstanceProcAddr next_gipa = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  PFN_vkGetDeviceProcAddr next_gdpa = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
  // The real instance, not NULL: some drivers and layers need it to resolve vkCreateDevice.
  auto next_create = reinterpret_cast<PFN_vkCreateDevice>(next_gipa(instance->instance, "vkCreateDevice"));
  if (!next_create) return VK_ERROR_INITIALIZATION_FAILED;

  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  const VkResult result = next_create(physicalDevice, pCreateInfo, pAllocator, pDevice);
  if (result != VK_SUCCESS) return result;

  auto data = std::make_unique<DeviceData>();
  data->device = *pDevice;
  data->physical_device = physicalDevice;
  data->instance = instance;
  data->reporter = instance->reporter.get();
  data->next_gdpa = next_gdpa;
  InitDeviceDispatchTable(*pDevice, next_gdpa, &data->dispatch);
  // vkSetDebugUtilsObjectNameEXT belongs to an instance extension: the chain may answer it only at instance
  // level. The layer hands its hook out wherever the chain has the function, so it must always be able to
  // pass the call down.
  if (!data->dispatch.SetDebugUtilsObjectNameEXT) {
    data->dispatch.SetDebugUtilsObjectNameEXT = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        instance->next_gipa(instance->instance, "vkSetDebugUtilsObjectNameEXT"));
  }
  data->state.history_tracked = instance->settings.TracksHistory();
  data->state.lifetime_tracked = data->state.history_tracked && (instance->settings.enabled_checks & kCheckLifetime);
  // Traces are followed for family traces, and for lifetime (a structure a pending trace reads is in use).
  data->state.traces_tracked =
      data->state.history_tracked && (instance->settings.enabled_checks & (kCheckTraces | kCheckLifetime));
  const LayerSettings& settings = instance->settings;
  data->state.instance_activity_snapshots =
      settings.capture == kCaptureAll &&
      (((settings.capture_warnings & kCaptureWarnDegenerateInstance) && settings.Reports(kSeverityInfo)) ||
       (settings.capture_warnings & kCaptureWarnFloatSpacing));
  data->state.features = ParseEnabledFeatures(*pCreateInfo);
  data->state.features.nv_ray_tracing = EnablesExtension(*pCreateInfo, VK_NV_RAY_TRACING_EXTENSION_NAME);
  QueryDeviceProperties(*instance, physicalDevice, data->state.features.nv_ray_tracing, &data->state.properties);
  data->state.properties.queue_families = QueueFamilies(*pCreateInfo);
  data->state.build_sizes.Init(*pDevice, data->dispatch.GetAccelerationStructureBuildSizesKHR);
  data->state.format_features.Init(physicalDevice, instance->dispatch.GetPhysicalDeviceFormatProperties);
  // Execution-time capture: needs the history (its records live there).
  if (data->state.history_tracked && instance->settings.capture != kCaptureOff) {
    const VkPhysicalDeviceType type = data->state.properties.core.deviceType;
    const bool address = data->state.features.buffer_device_address;
    const bool shader_objects = EnablesExtension(*pCreateInfo, "VK_EXT_shader_object");
    const bool reduce = CaptureReduces(settings.capture_method, type, address, shader_objects,
                                       (settings.capture_warnings & kCaptureWarnFloatSpacing) != 0);
    const bool gather = CaptureGathers(settings.capture_method, type, address, shader_objects);
    data->capture_pool =
        std::make_shared<CapturePool>(*pDevice, data->dispatch, data->state.properties.memory, reduce, gather);
    data->capture_tracker = std::make_unique<CaptureTracker>(*pDevice, data->dispatch);
    data->capture_aliases = std::make_unique<MemoryAliases>(*pDevice, data->dispatch,
                                                             data->state.properties.queue_families,
                                                             data->state.properties.max_buffer_size);
  }
  if (data->state.lifetime_tracked) {
    data->in_flight = std::make_unique<InFlight>(*pDevice, data->dispatch);
    // The layer's fence of a submission with captures is polled by the capture tracker as the app's would be: it
    // hears when the fence is reset for reuse.
    if (data->capture_tracker) {
      data->in_flight->SetFenceRecycledCallback(
          [](void* tracker, VkFence fence) { static_cast<CaptureTracker*>(tracker)->FenceRetired(fence); },
          data->capture_tracker.get());
    }
  }
  Devices().Insert(GetDispatchKey(*pDevice), std::move(data));
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDebugUtilsMessengerEXT(VkInstance instance,
                                                            const VkDebugUtilsMessengerCreateInfoEXT* pCreateInfo,
                                                            const VkAllocationCallbacks* pAllocator,
                                                            VkDebugUtilsMessengerEXT* pMessenger) {
  InstanceData* data = GetInstanceData(instance);
  if (!data || !data->dispatch.CreateDebugUtilsMessengerEXT) return VK_ERROR_EXTENSION_NOT_PRESENT;
  const VkResult result = data->dispatch.CreateDebugUtilsMessengerEXT(instance, pCreateInfo, pAllocator, pMessenger);
  if (result == VK_SUCCESS) data->reporter->AddMessenger(*pMessenger, *pCreateInfo);
  return result;
}

VKAPI_ATTR void VKAPI_CALL DestroyDebugUtilsMessengerEXT(VkInstance instance, VkDebugUtilsMessengerEXT messenger,
                                                         const VkAllocationCallbacks* pAllocator) {
  InstanceData* data = GetInstanceData(instance);
  if (!data) return;
  if (messenger) data->reporter->RemoveMessenger(messenger);
  if (data->dispatch.DestroyDebugUtilsMessengerEXT) {
    data->dispatch.DestroyDebugUtilsMessengerEXT(instance, messenger, pAllocator);
  }
}

}  // namespace hooks
}  // namespace asval
