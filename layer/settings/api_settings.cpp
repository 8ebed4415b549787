#include "api_settings.h"

#include <cstring>

namespace asval::settings_detail {
namespace {

// A well-formed chain is a handful of structures; this only stops a cyclic chain from hanging.
constexpr int kMaxChainLength = 4096;

void Warn(std::vector<std::string>* warnings, std::string message) {
  if (warnings != nullptr) warnings->push_back("asval settings: " + std::move(message));
}

}  // namespace

std::vector<ApiSettingEntry> CollectLayerSettingEntries(const void* pNext, const char* layer_name,
                                                        std::vector<std::string>* warnings) {
  std::vector<ApiSettingEntry> found;
  int create_info_index = 0;
  int chain_length = 0;
  for (auto* node = static_cast<const VkBaseInStructure*>(pNext); node != nullptr; node = node->pNext) {
    if (++chain_length > kMaxChainLength) {
      Warn(warnings, "the VkInstanceCreateInfo pNext chain is longer than " + std::to_string(kMaxChainLength) +
                         " structures (a cycle?); the rest of it is ignored");
      break;
    }
    if (node->sType != VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT) continue;
    const auto* info = reinterpret_cast<const VkLayerSettingsCreateInfoEXT*>(node);
    const std::string where = "VkLayerSettingsCreateInfoEXT #" + std::to_string(create_info_index++);
    if (info->settingCount > 0 && info->pSettings == nullptr) {
      Warn(warnings,
           where + " has settingCount " + std::to_string(info->settingCount) + " but pSettings NULL; it is ignored");
      continue;
    }
    for (uint32_t i = 0; i < info->settingCount; ++i) {
      const VkLayerSettingEXT& setting = info->pSettings[i];
      const std::string location = where + " pSettings[" + std::to_string(i) + "]";
      if (setting.pLayerName == nullptr) {
        Warn(warnings, location + " has pLayerName NULL; it is ignored");
        continue;
      }
      if (std::strcmp(setting.pLayerName, layer_name) != 0) continue;
      if (setting.pSettingName == nullptr) {
        Warn(warnings, location + " has pSettingName NULL; it is ignored");
        continue;
      }
      found.push_back({&setting, location});
    }
  }
  return found;
}

}  // namespace asval::settings_detail
