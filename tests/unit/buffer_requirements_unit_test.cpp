// Issue 25, item 7: the layer adds TRANSFER_SRC to build-input buffers at vkCreateBuffer (the capture copies from
// them where their memory is a dedicated allocation), so vkGetDeviceBufferMemoryRequirements and its KHR alias
// (maintenance4; what VMA sizes its pools with) must be answered for the same create info: memory sized by them must
// fit the buffer the driver makes. Lavapipe answers the same with and without TRANSFER_SRC, so this runs over a fake
// next element that records the usage each call brought down; the calls go through the layer's
// vkGetDeviceProcAddr, as an app's do (without the hook, the layer hands out the next element's function).
#include <vulkan/vk_layer.h>

#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <vector>

#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval {

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice device, const char* pName);

namespace {

struct FakeDispatchable {
  void* loader_table;
};
int g_instance_table, g_device_table;
FakeDispatchable g_instance_object{&g_instance_table}, g_gpu_object{&g_instance_table},
    g_device_object{&g_device_table};

struct Seen {
  std::vector<VkBufferUsageFlags> created, asked;
} g_seen;

VKAPI_ATTR VkResult VKAPI_CALL NextCreateDevice(VkPhysicalDevice, const VkDeviceCreateInfo*,
                                                const VkAllocationCallbacks*, VkDevice* device) {
  *device = reinterpret_cast<VkDevice>(&g_device_object);
  return VK_SUCCESS;
}
VKAPI_ATTR void VKAPI_CALL NextDestroyDevice(VkDevice, const VkAllocationCallbacks*) {}
VKAPI_ATTR VkResult VKAPI_CALL NextCreateBuffer(VkDevice, const VkBufferCreateInfo* info, const VkAllocationCallbacks*,
                                                VkBuffer* buffer) {
  g_seen.created.push_back(info->usage);
  *buffer = reinterpret_cast<VkBuffer>(uintptr_t{0x1000} + g_seen.created.size());
  return VK_SUCCESS;
}
VKAPI_ATTR void VKAPI_CALL NextDestroyBuffer(VkDevice, VkBuffer, const VkAllocationCallbacks*) {}
VKAPI_ATTR void VKAPI_CALL NextDeviceRequirements(VkDevice, const VkDeviceBufferMemoryRequirements* info,
                                                  VkMemoryRequirements2* out) {
  g_seen.asked.push_back(info->pCreateInfo->usage);
  // A driver whose requirements depend on the usage (the case that breaks an app's bind).
  out->memoryRequirements.size = (info->pCreateInfo->usage & VK_BUFFER_USAGE_TRANSFER_SRC_BIT) ? 2048 : 1024;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL NextGipa(VkInstance, const char* name) {
  if (std::strcmp(name, "vkCreateDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&NextCreateDevice);
  return nullptr;
}
VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL NextGdpa(VkDevice, const char* name) {
  if (std::strcmp(name, "vkDestroyDevice") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&NextDestroyDevice);
  if (std::strcmp(name, "vkCreateBuffer") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&NextCreateBuffer);
  if (std::strcmp(name, "vkDestroyBuffer") == 0) return reinterpret_cast<PFN_vkVoidFunction>(&NextDestroyBuffer);
  if (std::strcmp(name, "vkGetDeviceBufferMemoryRequirements") == 0 ||
      std::strcmp(name, "vkGetDeviceBufferMemoryRequirementsKHR") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&NextDeviceRequirements);
  }
  return nullptr;
}

// A device over the fake next element, capture on (the default settings).
class FakeDevice {
 public:
  FakeDevice() {
    auto instance = std::make_unique<InstanceData>();
    instance->instance = reinterpret_cast<VkInstance>(&g_instance_object);
    instance->next_gipa = &NextGipa;
    instance->reporter = std::make_unique<Reporter>(ReportSettings{});
    const DispatchKey key = GetDispatchKey(instance->instance);  // before the move below
    Instances().Insert(key, std::move(instance));
    VkLayerDeviceLink link{};
    link.pfnNextGetInstanceProcAddr = &NextGipa;
    link.pfnNextGetDeviceProcAddr = &NextGdpa;
    VkLayerDeviceCreateInfo chain{VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO};
    chain.function = VK_LAYER_LINK_INFO;
    chain.u.pLayerInfo = &link;
    VkDeviceCreateInfo create{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &chain};
    REQUIRE(hooks::CreateDevice(reinterpret_cast<VkPhysicalDevice>(&g_gpu_object), &create, nullptr, &device_) ==
            VK_SUCCESS);
    REQUIRE(GetDeviceData(device_)->capture_tracker);  // capture on: build inputs get TRANSFER_SRC
  }
  ~FakeDevice() {
    hooks::DestroyDevice(device_, nullptr);
    Instances().Remove(GetDispatchKey(reinterpret_cast<VkInstance>(&g_instance_object)));
  }
  VkDevice device() const { return device_; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
};

TEST_CASE("buffer requirements: vkGetDeviceBufferMemoryRequirements(KHR) answer for the usage vkCreateBuffer passes "
          "down",
          "[unit][capture][hook]") {
  FakeDevice fake;
  const VkDevice device = fake.device();
  for (const char* name : {"vkGetDeviceBufferMemoryRequirements", "vkGetDeviceBufferMemoryRequirementsKHR"}) {
    for (const VkBufferUsageFlags usage :
         {VkBufferUsageFlags{VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                             VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT},
          VkBufferUsageFlags{VK_BUFFER_USAGE_STORAGE_BUFFER_BIT}}) {
      g_seen = Seen{};
      auto create = reinterpret_cast<PFN_vkCreateBuffer>(GetDeviceProcAddr(device, "vkCreateBuffer"));
      auto requirements = reinterpret_cast<PFN_vkGetDeviceBufferMemoryRequirements>(GetDeviceProcAddr(device, name));
      auto destroy = reinterpret_cast<PFN_vkDestroyBuffer>(GetDeviceProcAddr(device, "vkDestroyBuffer"));
      REQUIRE(create);
      REQUIRE(requirements);
      VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
      info.size = 1000;
      info.usage = usage;
      const VkDeviceBufferMemoryRequirements query{VK_STRUCTURE_TYPE_DEVICE_BUFFER_MEMORY_REQUIREMENTS, nullptr, &info};
      VkMemoryRequirements2 answer{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
      requirements(device, &query, &answer);
      VkBuffer buffer = VK_NULL_HANDLE;
      REQUIRE(create(device, &info, nullptr, &buffer) == VK_SUCCESS);
      destroy(device, buffer, nullptr);
      CHECK(info.usage == usage);  // the app's create info is left as it was
      REQUIRE(g_seen.asked.size() == 1);
      REQUIRE(g_seen.created.size() == 1);
      CHECK(g_seen.asked[0] == g_seen.created[0]);
      const bool input = (usage & VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR) != 0;
      CHECK(((g_seen.created[0] & VK_BUFFER_USAGE_TRANSFER_SRC_BIT) != 0) == input);
      CHECK(answer.memoryRequirements.size == (input ? 2048u : 1024u));
    }
  }
}

}  // namespace
}  // namespace asval
