// Resolves every setting listed in asval_settings_defs.inc from environment, settings file and
// VkLayerSettingsCreateInfoEXT, in that order of precedence (Vulkan-Utility-Libraries'
// vkuGetLayerSettingValues).
#include <cstring>
#include <iterator>

#include "api_settings.h"
#include "layer_settings.h"
#include "setting_names.h"
#include "setting_readers.h"
#include "settings_file.h"

namespace asval {
namespace {

using settings_detail::ApiSettingEntry;
using settings_detail::EnumValueName;
using settings_detail::FlagName;
using settings_detail::RawSetting;
using settings_detail::SettingsFileLocation;
using settings_detail::SettingsFileValues;

// Every flag of every FLAGS setting; the empty last entry keeps the array valid if there were none.
constexpr FlagName kFlagNames[] = {
#define ASVAL_SETTING_FLAG(setting, flag, cpp_name, bit) {#setting, flag, bit},
#include "asval_settings_defs.inc"
    {"", "", 0},
};

// Every value of every ENUM setting, likewise.
constexpr EnumValueName kEnumValueNames[] = {
#define ASVAL_SETTING_ENUM_VALUE(setting, value, cpp_name) {#setting, value, cpp_name},
#include "asval_settings_defs.inc"
    {"", "", 0},
};

// Reads one raw value into its LayerSettings field; false (field untouched) with *error set on failure.
using ApplyFn = bool (*)(const RawSetting& raw, LayerSettings* settings, std::string* error);

struct SettingHandler {
  const char* name;
  const char* default_text;
  ApplyFn apply;
};

const SettingHandler kHandlers[] = {
#define ASVAL_SETTING_FLAGS(key, default_bits, default_text)                                          \
  {#key, default_text, [](const RawSetting& raw, LayerSettings* s, std::string* error) {              \
     return settings_detail::ReadFlags(raw, #key, kFlagNames, std::size(kFlagNames), &s->key, error); \
   }},
#define ASVAL_SETTING_INT(key, cpp_type, default_value, min, max, default_text)          \
  {#key, default_text, [](const RawSetting& raw, LayerSettings* s, std::string* error) { \
     return settings_detail::ReadIntegerAs(raw, min, max, &s->key, error);               \
   }},
#define ASVAL_SETTING_BOOL(key, default_value, default_text)                             \
  {#key, default_text, [](const RawSetting& raw, LayerSettings* s, std::string* error) { \
     return settings_detail::ReadBool(raw, &s->key, error);                              \
   }},
#define ASVAL_SETTING_STRING(key, default_value, default_text)                           \
  {#key, default_text, [](const RawSetting& raw, LayerSettings* s, std::string* error) { \
     return settings_detail::ReadString(raw, &s->key, error);                            \
   }},
#define ASVAL_SETTING_LIST(key, default_value, default_text)                             \
  {#key, default_text, [](const RawSetting& raw, LayerSettings* s, std::string* error) { \
     return settings_detail::ReadList(raw, &s->key, error);                              \
   }},
#define ASVAL_SETTING_ENUM(key, cpp_type, default_value, default_text)                                               \
  {#key, default_text, [](const RawSetting& raw, LayerSettings* s, std::string* error) {                             \
     return settings_detail::ReadEnumAs(raw, #key, kEnumValueNames, std::size(kEnumValueNames), &s->key, error); \
   }},
#include "asval_settings_defs.inc"
};

const SettingHandler* FindHandler(const char* name) {
  for (const SettingHandler& handler : kHandlers) {
    if (std::strcmp(handler.name, name) == 0) return &handler;
  }
  return nullptr;
}

void Warn(std::vector<std::string>* warnings, std::string message) {
  if (warnings != nullptr) warnings->push_back("asval settings: " + std::move(message));
}

std::string DefaultNote(const SettingHandler& handler) {
  const std::string shown = *handler.default_text != '\0' ? handler.default_text : "empty";
  return std::string("; ") + handler.name + " keeps its default (" + shown + ")";
}

// The settings file: found, read, and checked for keys of this layer that name no setting.
SettingsFileValues LoadSettingsFile(const SettingsSources& sources, std::string* path,
                                    std::vector<std::string>* warnings) {
  const SettingsFileLocation location = settings_detail::FindSettingsFile(sources);
  *path = location.path;
  SettingsFileValues values;
  if (!settings_detail::ReadSettingsFile(location.path, &values)) {
    // Only worth a word when the user pointed at it: VUL would not look further either.
    if (location.origin == SettingsFileLocation::Origin::kLayerSettingsPath) {
      Warn(warnings,
           "VK_LAYER_SETTINGS_PATH leads to '" + location.path + "', which cannot be read; no settings file is used");
    }
    return values;
  }
  const std::string prefix = settings_detail::FileKeyPrefix(kLayerName);
  for (const auto& [key, value] : values) {
    if (key.compare(0, prefix.size(), prefix) != 0) continue;  // another layer's setting
    if (FindHandler(key.c_str() + prefix.size()) == nullptr) {
      Warn(warnings, "settings file '" + location.path + "': unknown setting '" + key + "'; it is ignored");
    }
  }
  return values;
}

// The API entries that can be applied, in chain order. Every entry of this layer is checked here, used or
// not, so that an application's mistake is reported even when an environment variable hides it; a
// malformed or unknown entry is ignored (a later entry for the same setting may then apply).
std::vector<ApiSettingEntry> UsableApiEntries(const void* pNext, std::vector<std::string>* warnings) {
  std::vector<ApiSettingEntry> usable;
  for (ApiSettingEntry& api : settings_detail::CollectLayerSettingEntries(pNext, kLayerName, warnings)) {
    const char* name = api.entry->pSettingName;
    const SettingHandler* handler = FindHandler(name);
    if (handler == nullptr) {
      Warn(warnings, api.location + ": unknown setting '" + name + "' for " + kLayerName + "; it is ignored");
      continue;
    }
    LayerSettings scratch;
    std::string error;
    if (!handler->apply(RawSetting{api.location, {}, api.entry}, &scratch, &error)) {
      Warn(warnings, api.location + " (" + name + "): " + error + "; the entry is ignored");
      continue;
    }
    usable.push_back(std::move(api));
  }
  return usable;
}

// The value that wins for one setting, or false when no source sets it.
bool FindRawSetting(const SettingHandler& handler, const SettingsSources& sources, const SettingsFileValues& file,
                    const std::string& file_path, const std::vector<ApiSettingEntry>& api, RawSetting* raw) {
  for (const std::string& env_name : settings_detail::EnvSettingNames(kLayerName, handler.name)) {
    std::string value = settings_detail::EnvValue(sources, env_name.c_str());
    if (!value.empty()) {
      *raw = RawSetting{"environment variable " + env_name, std::move(value), nullptr};
      return true;
    }
  }
  const std::string file_key = settings_detail::FileSettingKey(kLayerName, handler.name);
  if (const auto it = file.find(file_key); it != file.end() && !it->second.empty()) {
    *raw = RawSetting{"settings file '" + file_path + "', " + file_key, it->second, nullptr};
    return true;
  }
  for (const ApiSettingEntry& entry : api) {
    if (std::strcmp(entry.entry->pSettingName, handler.name) == 0) {
      *raw = RawSetting{entry.location + " (" + handler.name + ")", {}, entry.entry};
      return true;
    }
  }
  return false;
}

}  // namespace

LayerSettings LoadLayerSettings(const SettingsSources& sources, const void* instance_create_info_pnext,
                                std::vector<std::string>* warnings) {
  std::string file_path;
  const SettingsFileValues file = LoadSettingsFile(sources, &file_path, warnings);
  const std::vector<ApiSettingEntry> api = UsableApiEntries(instance_create_info_pnext, warnings);

  LayerSettings settings;
  for (const SettingHandler& handler : kHandlers) {
    RawSetting raw;
    if (!FindRawSetting(handler, sources, file, file_path, api, &raw)) continue;
    std::string error;
    if (!handler.apply(raw, &settings, &error)) Warn(warnings, raw.origin + ": " + error + DefaultNote(handler));
  }
  return settings;
}

}  // namespace asval
