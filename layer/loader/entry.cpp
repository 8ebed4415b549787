// The loader interface: negotiation, the two GetProcAddr functions and the v0 introspection functions.
// These are the only symbols the library exports (see VkLayer_asval_as_validation.map).
#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

#include <cstring>

#include "layer_data.h"
#include "layer_info.h"
#include "vk_intercepts.h"

#define ASVAL_EXPORT extern "C" __attribute__((visibility("default")))

namespace asval {

namespace {

template <typename T>
VkResult FillArray(const T* items, uint32_t item_count, uint32_t* count, T* out) {
  if (!out) {
    *count = item_count;
    return VK_SUCCESS;
  }
  const uint32_t n = *count < item_count ? *count : item_count;
  for (uint32_t i = 0; i < n; ++i) out[i] = items[i];
  *count = n;
  return n < item_count ? VK_INCOMPLETE : VK_SUCCESS;
}

VkLayerProperties LayerProperties() {
  VkLayerProperties p{};
  std::strncpy(p.layerName, kLayerName, sizeof(p.layerName) - 1);
  std::strncpy(p.description, kLayerDescription, sizeof(p.description) - 1);
  p.specVersion = kLayerSpecVersion;
  p.implementationVersion = kLayerImplementationVersion;
  return p;
}

}  // namespace

VKAPI_ATTR VkResult VKAPI_CALL EnumerateInstanceLayerProperties(uint32_t* pPropertyCount,
                                                                VkLayerProperties* pProperties) {
  const VkLayerProperties p = LayerProperties();
  return FillArray(&p, 1, pPropertyCount, pProperties);
}

VKAPI_ATTR VkResult VKAPI_CALL EnumerateDeviceLayerProperties(VkPhysicalDevice, uint32_t* pPropertyCount,
                                                              VkLayerProperties* pProperties) {
  const VkLayerProperties p = LayerProperties();
  return FillArray(&p, 1, pPropertyCount, pProperties);
}

// With pLayerName naming this layer: its own extensions. Any other name (NULL included) is not ours to
// answer at instance level (the loader aggregates; LLP_LAYER_15).
VKAPI_ATTR VkResult VKAPI_CALL EnumerateInstanceExtensionProperties(const char* pLayerName, uint32_t* pPropertyCount,
                                                                    VkExtensionProperties* pProperties) {
  if (pLayerName && std::strcmp(pLayerName, kLayerName) == 0) {
    return FillArray(kInstanceExtensions, static_cast<uint32_t>(std::size(kInstanceExtensions)), pPropertyCount,
                     pProperties);
  }
  return VK_ERROR_LAYER_NOT_PRESENT;
}

// The layer adds no device extension. For our own name: none; for any other name: ask down (LLP_LAYER_16).
VKAPI_ATTR VkResult VKAPI_CALL EnumerateDeviceExtensionProperties(VkPhysicalDevice physicalDevice,
                                                                  const char* pLayerName, uint32_t* pPropertyCount,
                                                                  VkExtensionProperties* pProperties) {
  if (pLayerName && std::strcmp(pLayerName, kLayerName) == 0) {
    *pPropertyCount = 0;
    return VK_SUCCESS;
  }
  InstanceData* data = physicalDevice ? GetInstanceData(physicalDevice) : nullptr;
  if (!data || !data->dispatch.EnumerateDeviceExtensionProperties) return VK_ERROR_LAYER_NOT_PRESENT;
  return data->dispatch.EnumerateDeviceExtensionProperties(physicalDevice, pLayerName, pPropertyCount, pProperties);
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance, const char* pName);
VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* pName);

// Functions the layer answers for itself whatever the handle.
static PFN_vkVoidFunction FindLayerOwnFunction(const char* name) {
  struct Own {
    const char* name;
    PFN_vkVoidFunction fn;
  };
  static const Own kOwn[] = {
      {"vkGetInstanceProcAddr", reinterpret_cast<PFN_vkVoidFunction>(&GetInstanceProcAddr)},
      {"vkGetDeviceProcAddr", reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr)},
      {"vkEnumerateInstanceLayerProperties", reinterpret_cast<PFN_vkVoidFunction>(&EnumerateInstanceLayerProperties)},
      {"vkEnumerateInstanceExtensionProperties",
       reinterpret_cast<PFN_vkVoidFunction>(&EnumerateInstanceExtensionProperties)},
      {"vkEnumerateDeviceLayerProperties", reinterpret_cast<PFN_vkVoidFunction>(&EnumerateDeviceLayerProperties)},
      {"vkEnumerateDeviceExtensionProperties",
       reinterpret_cast<PFN_vkVoidFunction>(&EnumerateDeviceExtensionProperties)},
  };
  for (const Own& own : kOwn) {
    if (std::strcmp(own.name, name) == 0) return own.fn;
  }
  return nullptr;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance, const char* pName) {
  if (!pName) return nullptr;
  if (PFN_vkVoidFunction own = FindLayerOwnFunction(pName)) return own;
  if (std::strcmp(pName, "vkCreateInstance") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&hooks::CreateInstance);
  const hooks::InterceptEntry* hook = hooks::FindIntercept(pName);
  if (!instance) {
    // Before an instance exists only global functions can be asked for; none of the others are ours.
    return nullptr;
  }
  InstanceData* data = GetInstanceData(instance);
  if (!data) return nullptr;
  PFN_vkVoidFunction next = data->next_gipa(instance, pName);
  // A function the chain below does not offer (extension not enabled) is not offered by the layer either.
  if (hook && next) return hook->fn;
  return next;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* pName) {
  if (!pName || !device) return nullptr;
  if (std::strcmp(pName, "vkGetDeviceProcAddr") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&GetDeviceProcAddr);
  DeviceData* data = GetDeviceData(device);
  if (!data) return nullptr;
  PFN_vkVoidFunction next = data->next_gdpa(device, pName);
  const hooks::InterceptEntry* hook = hooks::FindIntercept(pName);
  if (hook && hook->device_level && next) return hook->fn;
  return next;
}

}  // namespace asval

ASVAL_EXPORT VKAPI_ATTR VkResult VKAPI_CALL
vkNegotiateLoaderLayerInterfaceVersion(VkNegotiateLayerInterface* pVersionStruct) {
  if (!pVersionStruct || pVersionStruct->sType != LAYER_NEGOTIATE_INTERFACE_STRUCT) {
    return VK_ERROR_INITIALIZATION_FAILED;
  }
  // Interface version 2 is what this loader generation speaks; older loaders cannot chain this layer.
  if (pVersionStruct->loaderLayerInterfaceVersion < 2) return VK_ERROR_INITIALIZATION_FAILED;
  if (pVersionStruct->loaderLayerInterfaceVersion > CURRENT_LOADER_LAYER_INTERFACE_VERSION) {
    pVersionStruct->loaderLayerInterfaceVersion = CURRENT_LOADER_LAYER_INTERFACE_VERSION;
  }
  pVersionStruct->pfnGetInstanceProcAddr = &asval::GetInstanceProcAddr;
  pVersionStruct->pfnGetDeviceProcAddr = &asval::GetDeviceProcAddr;
  pVersionStruct->pfnGetPhysicalDeviceProcAddr = nullptr;  // the layer adds no physical-device function
  return VK_SUCCESS;
}

ASVAL_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetInstanceProcAddr(VkInstance instance, const char* pName) {
  return asval::GetInstanceProcAddr(instance, pName);
}

ASVAL_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetDeviceProcAddr(VkDevice device, const char* pName) {
  return asval::GetDeviceProcAddr(device, pName);
}

ASVAL_EXPORT VKAPI_ATTR VkResult VKAPI_CALL vkEnumerateInstanceLayerProperties(uint32_t* pPropertyCount,
                                                                              VkLayerProperties* pProperties) {
  return asval::EnumerateInstanceLayerProperties(pPropertyCount, pProperties);
}

ASVAL_EXPORT VKAPI_ATTR VkResult VKAPI_CALL vkEnumerateInstanceExtensionProperties(
    const char* pLayerName, uint32_t* pPropertyCount, VkExtensionProperties* pProperties) {
  return asval::EnumerateInstanceExtensionProperties(pLayerName, pPropertyCount, pProperties);
}

ASVAL_EXPORT VKAPI_ATTR VkResult VKAPI_CALL vkEnumerateDeviceLayerProperties(VkPhysicalDevice physicalDevice,
                                                                            uint32_t* pPropertyCount,
                                                                            VkLayerProperties* pProperties) {
  return asval::EnumerateDeviceLayerProperties(physicalDevice, pPropertyCount, pProperties);
}

ASVAL_EXPORT VKAPI_ATTR VkResult VKAPI_CALL vkEnumerateDeviceExtensionProperties(VkPhysicalDevice physicalDevice,
                                                                                const char* pLayerName,
                                                                                uint32_t* pPropertyCount,
                                                                                VkExtensionProperties* pProperties) {
  return asval::EnumerateDeviceExtensionProperties(physicalDevice, pLayerName, pPropertyCount, pProperties);
}
