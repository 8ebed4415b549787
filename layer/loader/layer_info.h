#pragma once
// The layer's identity, as the manifest states it.
#include <vulkan/vulkan.h>

#include "layer_settings.h"  // kLayerName, from the settings source of truth

namespace asval {

inline constexpr const char* kLayerDescription = "asval: validates acceleration-structure commands";
inline constexpr uint32_t kLayerImplementationVersion = 1;
inline constexpr uint32_t kLayerSpecVersion = VK_HEADER_VERSION_COMPLETE;

// Instance extensions the layer implements itself.
inline constexpr VkExtensionProperties kInstanceExtensions[] = {
    {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, 2},
    {"VK_EXT_layer_settings", 2},
};

}  // namespace asval
