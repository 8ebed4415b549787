// Public API of the asval_settings library: the layer's settings as typed values, and how they are read.
//
// The fields and their defaults come from generated/asval_settings_defs.inc, which
// scripts/gen_settings.py writes from scripts/settings.json, the same source as the layer manifest and
// vk_layer_settings.txt, so the three cannot disagree. Settings are read once, at vkCreateInstance; the
// struct is plain data afterwards and safe to read from any thread.
//
// This header needs no Vulkan header: the pNext chain is taken as `const void*`.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace asval {

// Bits of the FLAGS settings (report_flags: kSeverityError, kSeverityWarn, kSeverityInfo).
enum LayerSettingFlagBits : uint32_t {
#define ASVAL_SETTING_FLAG(setting, flag, cpp_name, bit) cpp_name = bit,
#include "asval_settings_defs.inc"
};

// The type of each ENUM setting, its enumerators numbered from 0 in the manifest's order
// (capture: CaptureMode, with kCaptureOff, kCaptureUpdates, kCaptureAll).
#define ASVAL_SETTING_ENUM_TYPE(cpp_type, ...) enum cpp_type : uint32_t { __VA_ARGS__ };
#include "asval_settings_defs.inc"

// "VK_LAYER_ASVAL_as_validation": the pLayerName that VkLayerSettingsCreateInfoEXT entries must carry.
inline constexpr const char kLayerName[] =
#define ASVAL_SETTINGS_LAYER_NAME(name) name
#include "asval_settings_defs.inc"
    ;

struct LayerSettings {
  // One field per setting, named after its key, initialised to the manifest default:
  //   uint32_t report_flags;                      LayerSettingFlagBits
  //   CaptureMode capture;                        kCaptureOff, kCaptureUpdates or kCaptureAll
  //   uint32_t capture_budget_mb;                 per recording of a command buffer, 1..65536
  //   uint32_t duplicate_message_limit;           0 = unlimited
  //   std::vector<std::string> message_id_filter; VUIDs, VUID suffixes or message-id hashes, as written
  //   std::string report_file;                    JSON-lines report path, empty = none
  //   bool log_to_stderr;
#define ASVAL_SETTING_FLAGS(key, default_bits, default_text) uint32_t key = default_bits;
#define ASVAL_SETTING_INT(key, cpp_type, default_value, min, max, default_text) cpp_type key = default_value;
#define ASVAL_SETTING_BOOL(key, default_value, default_text) bool key = default_value;
#define ASVAL_SETTING_STRING(key, default_value, default_text) std::string key = default_value;
#define ASVAL_SETTING_LIST(key, default_value, default_text) std::vector<std::string> key = default_value;
#define ASVAL_SETTING_ENUM(key, cpp_type, default_value, default_text) cpp_type key = default_value;
#include "asval_settings_defs.inc"

  bool Reports(LayerSettingFlagBits severity) const { return (report_flags & severity) != 0; }
  // A family that needs the recorded operations is enabled (history, copies for dst-03561, lifetime).
  bool TracksHistory() const { return (enabled_checks & (kCheckHistory | kCheckCopies | kCheckLifetime | kCheckTraces)) != 0; }

  friend bool operator==(const LayerSettings& a, const LayerSettings& b) {
    bool same = true;
#define ASVAL_SETTING_FLAGS(key, ...) same = same && a.key == b.key;
#define ASVAL_SETTING_INT(key, ...) same = same && a.key == b.key;
#define ASVAL_SETTING_BOOL(key, ...) same = same && a.key == b.key;
#define ASVAL_SETTING_STRING(key, ...) same = same && a.key == b.key;
#define ASVAL_SETTING_LIST(key, ...) same = same && a.key == b.key;
#define ASVAL_SETTING_ENUM(key, ...) same = same && a.key == b.key;
#include "asval_settings_defs.inc"
    return same;
  }
  friend bool operator!=(const LayerSettings& a, const LayerSettings& b) { return !(a == b); }
};

// Where settings come from, so that tests can replace the process environment and working directory.
struct SettingsSources {
  // Value of an environment variable; "" when unset. Unset and empty are the same, as in VUL.
  // Also consulted for XDG_DATA_HOME, HOME and VK_LAYER_SETTINGS_PATH.
  std::function<std::string(const char* name)> getenv;
  // Directory searched last for vk_layer_settings.txt; empty means a relative "vk_layer_settings.txt".
  std::string cwd;

  // The real process environment (std::getenv) and current working directory.
  static SettingsSources FromProcess();
};

// Reads every setting. Per setting, the first source that sets it wins (Vulkan-Utility-Libraries order):
//   1. environment: VK_ASVAL_AS_VALIDATION_<SETTING>, VK_AS_VALIDATION_<SETTING>, VK_<SETTING>
//      (first non-empty);
//   2. the first vk_layer_settings.txt found (see FindSettingsFile in settings_file.h), key
//      asval_as_validation.<setting>;
//   3. VkLayerSettingsCreateInfoEXT structures in `instance_create_info_pnext` (the pNext of
//      VkInstanceCreateInfo), first entry with pLayerName == kLayerName and the setting's name.
// An empty environment or file value counts as unset. A malformed value, an unknown setting for this
// layer (file or API) or a malformed API structure adds a human-readable line to `warnings` (may be
// null) and never aborts: a malformed environment or file value leaves the setting at its default (the
// next source is not consulted, as in VUL); a malformed or unknown API entry is ignored, so a later
// well-formed entry for the same setting may apply. Value types accepted: see setting_readers.h.
// Not for hot paths: it allocates and reads files.
LayerSettings LoadLayerSettings(const SettingsSources& sources, const void* instance_create_info_pnext,
                                std::vector<std::string>* warnings);

// Same, with SettingsSources::FromProcess().
LayerSettings LoadLayerSettings(const void* instance_create_info_pnext, std::vector<std::string>* warnings);

}  // namespace asval
