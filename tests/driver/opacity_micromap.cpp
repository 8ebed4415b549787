#include "opacity_micromap.h"

#include <cstring>

#include "driver_dispatch.h"
#include "test_driver_api.h"

namespace asval_test_driver {

void ReportOpacityMicromapFeatures(void* chain) {
  for (auto* s = static_cast<VkBaseOutStructure*>(chain); s != nullptr; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_FEATURES_EXT) {
      auto* features = reinterpret_cast<VkPhysicalDeviceOpacityMicromapFeaturesEXT*>(s);
      features->micromap = kAsvalTestDriverMicromap;
      features->micromapCaptureReplay = kAsvalTestDriverMicromapCaptureReplay;
      features->micromapHostCommands = kAsvalTestDriverMicromapHostCommands;
    }
  }
}

VkBufferUsageFlags MicromapUsageBelow(bool enabled, VkBufferUsageFlags usage) {
  if (!enabled) return usage;
  usage &= ~static_cast<VkBufferUsageFlags>(VK_BUFFER_USAGE_MICROMAP_BUILD_INPUT_READ_ONLY_BIT_EXT |
                                            VK_BUFFER_USAGE_MICROMAP_STORAGE_BIT_EXT);
  return usage != 0 ? usage : static_cast<VkBufferUsageFlags>(VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
}

OpacityMicromapProperties::OpacityMicromapProperties(VkPhysicalDeviceProperties2* properties)
    : out_(properties, VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_PROPERTIES_EXT) {}

OpacityMicromapProperties::~OpacityMicromapProperties() {
  if (out_.structure() == nullptr) return;
  auto* properties = reinterpret_cast<VkPhysicalDeviceOpacityMicromapPropertiesEXT*>(out_.structure());
  properties->maxOpacity2StateSubdivisionLevel = kAsvalTestDriverMaxOpacity2StateSubdivisionLevel;
  properties->maxOpacity4StateSubdivisionLevel = kAsvalTestDriverMaxOpacity4StateSubdivisionLevel;
}  // out_ puts it back in the chain

Micromaps::Micromaps() = default;
Micromaps::~Micromaps() = default;

VkResult Micromaps::Create(const VkMicromapCreateInfoEXT& info, VkMicromapEXT* micromap) {
  auto copy = std::make_unique<Micromap>();
  copy->info = info;
  copy->info.pNext = nullptr;
  // A non-dispatchable handle is 64 bits wide: the object's address.
  *micromap = reinterpret_cast<VkMicromapEXT>(copy.get());
  std::lock_guard<std::mutex> lock(lock_);
  micromaps_[*micromap] = std::move(copy);
  return VK_SUCCESS;
}

void Micromaps::Destroy(VkMicromapEXT micromap) {
  std::lock_guard<std::mutex> lock(lock_);
  micromaps_.erase(micromap);  // VK_NULL_HANDLE, or a handle of no micromap, is nothing to erase
}

namespace {

VKAPI_ATTR VkResult VKAPI_CALL CreateMicromapEXT(VkDevice handle, const VkMicromapCreateInfoEXT* info,
                                                 const VkAllocationCallbacks*, VkMicromapEXT* micromap) {
  return FindDevice(handle)->micromaps->Create(*info, micromap);
}

VKAPI_ATTR void VKAPI_CALL DestroyMicromapEXT(VkDevice handle, VkMicromapEXT micromap, const VkAllocationCallbacks*) {
  FindDevice(handle)->micromaps->Destroy(micromap);
}

VKAPI_ATTR void VKAPI_CALL GetMicromapBuildSizesEXT(VkDevice, VkAccelerationStructureBuildTypeKHR,
                                                    const VkMicromapBuildInfoEXT* info,
                                                    VkMicromapBuildSizesInfoEXT* sizes) {
  sizes->micromapSize = AsvalTestDriverMicromapSize(*info);
  sizes->buildScratchSize = kAsvalTestDriverMicromapBuildScratchSize;
  sizes->discardable = VK_FALSE;
}

// Micromaps have no contents here: nothing to build.
VKAPI_ATTR void VKAPI_CALL CmdBuildMicromapsEXT(VkCommandBuffer, uint32_t, const VkMicromapBuildInfoEXT*) {}

}  // namespace

PFN_vkVoidFunction OpacityMicromapFunction(const char* name) {
#define ASVAL_DRIVER_MICROMAP_HOOK(fn) \
  if (std::strcmp(name, "vk" #fn) == 0) return reinterpret_cast<PFN_vkVoidFunction>(&fn);
  ASVAL_DRIVER_MICROMAP_HOOK(CreateMicromapEXT)
  ASVAL_DRIVER_MICROMAP_HOOK(DestroyMicromapEXT)
  ASVAL_DRIVER_MICROMAP_HOOK(GetMicromapBuildSizesEXT)
  ASVAL_DRIVER_MICROMAP_HOOK(CmdBuildMicromapsEXT)
#undef ASVAL_DRIVER_MICROMAP_HOOK
  return nullptr;
}

}  // namespace asval_test_driver
