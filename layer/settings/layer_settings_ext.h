// VK_EXT_layer_settings, declared here because the Vulkan 1.3.239 headers that Debian 12 ships predate it
// (grep -c LAYER_SETTINGS /usr/include/vulkan/vulkan_core.h gives 0). Values and layouts are those of the
// newer vulkan_core.h; with newer headers the guard makes this file a no-op.
//
// Not part of the installed API: the settings library reads these structures, and tests and examples
// include it to build VkLayerSettingsCreateInfoEXT chains.
#pragma once

#include <vulkan/vulkan_core.h>

#ifndef VK_EXT_layer_settings
#define VK_EXT_layer_settings 1
#define VK_EXT_LAYER_SETTINGS_SPEC_VERSION 2
#define VK_EXT_LAYER_SETTINGS_EXTENSION_NAME "VK_EXT_layer_settings"

// A #define: the enumerator cannot be added to this header version's VkStructureType. The cast is
// well defined because the enum's range reaches 0x7FFFFFFF (VK_STRUCTURE_TYPE_MAX_ENUM).
#define VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT ((VkStructureType)1000496000)

typedef enum VkLayerSettingTypeEXT {
  VK_LAYER_SETTING_TYPE_BOOL32_EXT = 0,
  VK_LAYER_SETTING_TYPE_INT32_EXT = 1,
  VK_LAYER_SETTING_TYPE_INT64_EXT = 2,
  VK_LAYER_SETTING_TYPE_UINT32_EXT = 3,
  VK_LAYER_SETTING_TYPE_UINT64_EXT = 4,
  VK_LAYER_SETTING_TYPE_FLOAT32_EXT = 5,
  VK_LAYER_SETTING_TYPE_FLOAT64_EXT = 6,
  VK_LAYER_SETTING_TYPE_STRING_EXT = 7,
  VK_LAYER_SETTING_TYPE_MAX_ENUM_EXT = 0x7FFFFFFF
} VkLayerSettingTypeEXT;

typedef struct VkLayerSettingEXT {
  const char* pLayerName;
  const char* pSettingName;
  VkLayerSettingTypeEXT type;
  uint32_t valueCount;
  const void* pValues;
} VkLayerSettingEXT;

typedef struct VkLayerSettingsCreateInfoEXT {
  VkStructureType sType;
  const void* pNext;
  uint32_t settingCount;
  const VkLayerSettingEXT* pSettings;
} VkLayerSettingsCreateInfoEXT;
#endif  // VK_EXT_layer_settings
