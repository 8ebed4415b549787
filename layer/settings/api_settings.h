// Collecting this layer's entries from the VkLayerSettingsCreateInfoEXT structures of a
// VkInstanceCreateInfo pNext chain (every such structure, in chain order, like VUL's
// vkuNextLayerSettingsCreateInfo loop).
#pragma once

#include <string>
#include <vector>

#include "layer_settings_ext.h"

namespace asval::settings_detail {

struct ApiSettingEntry {
  const VkLayerSettingEXT* entry;
  std::string location;  // "VkLayerSettingsCreateInfoEXT #0 pSettings[2]", for messages
};

// Entries whose pLayerName equals `layer_name` and whose pSettingName is not NULL, in chain order
// (the caller applies the first usable one per setting). Entries for other layers are skipped silently.
// Structural problems go to `warnings` and the affected part is skipped: a structure with settingCount
// > 0 and pSettings NULL, an entry with a NULL pLayerName or (for this layer) a NULL pSettingName, and a
// chain that does not end within 4096 structures (a cycle).
std::vector<ApiSettingEntry> CollectLayerSettingEntries(const void* pNext, const char* layer_name,
                                                        std::vector<std::string>* warnings);

}  // namespace asval::settings_detail
