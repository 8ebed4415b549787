// The layer never swallows a call: vkSetDebugUtilsObjectNameEXT reaches the next element even when that
// element answers it only at instance level (VK_EXT_debug_utils is an instance extension; an app that did not
// enable it still gets the function from vkGetInstanceProcAddr, and the Khronos layer below must see the call
// to report that bug). vkCreateDevice runs over a fake next element; no driver.
#include <vulkan/vk_layer.h>

#include <catch2/catch_test_macros.hpp>

#include <cstring>

#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval {
namespace {

struct FakeDispatchable {
  void* loader_table;
};
int g_instance_table, g_device_table;
FakeDispatchable g_instance_object{&g_instance_table}, g_gpu_object{&g_instance_table},
    g_device_object{&g_device_table};
int g_names_passed_down = 0;

VKAPI_ATTR VkResult VKAPI_CALL NextCreateDevice(VkPhysicalDevice, const VkDeviceCreateInfo*,
                                                const VkAllocationCallbacks*, VkDevice* device) {
  *device = reinterpret_cast<VkDevice>(&g_device_object);
  return VK_SUCCESS;
}
VKAPI_ATTR VkResult VKAPI_CALL NextSetObjectName(VkDevice, const VkDebugUtilsObjectNameInfoEXT*) {
  ++g_names_passed_down;
  return VK_ERROR_EXTENSION_NOT_PRESENT;  // what a next element that was not asked for the extension may say
}
VKAPI_ATTR void VKAPI_CALL NextDestroyDevice(VkDevice, const VkAllocationCallbacks*) {}

// The next element: vkSetDebugUtilsObjectNameEXT only at instance level, not through vkGetDeviceProcAddr.
VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL NextGipa(VkInstance, const char* name) {
  if (std::strcmp(name, "vkCreateDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&NextCreateDevice);
  if (std::strcmp(name, "vkSetDebugUtilsObjectNameEXT") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&NextSetObjectName);
  }
  return nullptr;
}
VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL NextGdpa(VkDevice, const char* name) {
  if (std::strcmp(name, "vkDestroyDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&NextDestroyDevice);
  return nullptr;
}

TEST_CASE("transparency: vkSetDebugUtilsObjectNameEXT is passed down when the chain has it only at instance level",
          "[hook]") {
  auto instance = std::make_unique<InstanceData>();
  instance->instance = reinterpret_cast<VkInstance>(&g_instance_object);
  instance->next_gipa = &NextGipa;
  instance->reporter = std::make_unique<Reporter>(ReportSettings{});
  const DispatchKey key = GetDispatchKey(instance->instance);
  Instances().Insert(key, std::move(instance));

  VkLayerDeviceLink link{};
  link.pfnNextGetInstanceProcAddr = &NextGipa;
  link.pfnNextGetDeviceProcAddr = &NextGdpa;
  VkLayerDeviceCreateInfo chain{VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO};
  chain.function = VK_LAYER_LINK_INFO;
  chain.u.pLayerInfo = &link;
  VkDeviceCreateInfo create{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &chain};
  VkDevice device = VK_NULL_HANDLE;
  REQUIRE(hooks::CreateDevice(reinterpret_cast<VkPhysicalDevice>(&g_gpu_object), &create, nullptr, &device) ==
          VK_SUCCESS);

  VkDebugUtilsObjectNameInfoEXT name{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  name.objectType = VK_OBJECT_TYPE_DEVICE;
  name.objectHandle = reinterpret_cast<uint64_t>(device);
  name.pObjectName = "device";
  // The next element's answer comes back unchanged (it used to be VK_SUCCESS, without the call going down).
  CHECK(hooks::SetDebugUtilsObjectNameEXT(device, &name) == VK_ERROR_EXTENSION_NOT_PRESENT);
  CHECK(g_names_passed_down == 1);

  hooks::DestroyDevice(device, nullptr);
  Instances().Remove(GetDispatchKey(reinterpret_cast<VkInstance>(&g_instance_object)));
}

}  // namespace
}  // namespace asval
