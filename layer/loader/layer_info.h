#pragma once
// The layer's identity, as the manifest states it.
#include <vulkan/vulkan.h>

#include "layer_settings.h"  // kLayerName, from the settings source of truth

namespace asval {

inline constexpr const char* kLayerDescription = "asval: validates acceleration-structure commands";
// From CMake (layer/loader/CMakeLists.txt), which writes the same number into the manifests.
#ifndef ASVAL_IMPLEMENTATION_VERSION
#error "ASVAL_IMPLEMENTATION_VERSION is defined by layer/loader/CMakeLists.txt"
#endif
inline constexpr uint32_t kLayerImplementationVersion = ASVAL_IMPLEMENTATION_VERSION;
inline constexpr uint32_t kLayerSpecVersion = VK_HEADER_VERSION_COMPLETE;

// Instance extensions the layer implements itself.
inline constexpr VkExtensionProperties kInstanceExtensions[] = {
    {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, 2},
    {"VK_EXT_layer_settings", 2},
};

}  // namespace asval
