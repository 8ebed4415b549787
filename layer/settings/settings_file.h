// Finding and parsing vk_layer_settings.txt, as Vulkan-Utility-Libraries' layer_settings_manager.cpp
// does it on Linux (FindSettingsFile, ParseSettingsFile). Follows VUL's code where its documentation
// differs: the vkconfig file is checked first, not the working directory.
#pragma once

#include <map>
#include <string>
#include <string_view>

#include "layer_settings.h"

namespace asval::settings_detail {

struct SettingsFileLocation {
  enum class Origin {
    kVkconfig,           // $XDG_DATA_HOME (or $HOME/.local/share) /vulkan/settings.d/vk_layer_settings.txt
    kLayerSettingsPath,  // $VK_LAYER_SETTINGS_PATH, "/vk_layer_settings.txt" appended for a directory
    kWorkingDirectory,   // <cwd>/vk_layer_settings.txt
  };
  std::string path;  // may not exist: VUL stops at an existing VK_LAYER_SETTINGS_PATH directory even
                     // when it holds no vk_layer_settings.txt, and the working-directory file is optional
  Origin origin = Origin::kWorkingDirectory;
};

// sources.getenv(name), or "" when the callback is not set.
std::string EnvValue(const SettingsSources& sources, const char* name);

// The one file whose settings are read; only the first candidate found is used:
//   1. the vkconfig file, if it is a regular file;
//   2. VK_LAYER_SETTINGS_PATH, if stat() succeeds (a directory gets /vk_layer_settings.txt appended);
//   3. the working directory's vk_layer_settings.txt.
SettingsFileLocation FindSettingsFile(const SettingsSources& sources);

// key -> value. Everything after the first '#' on a line is a comment (even inside a value); a line
// splits at its first '='; key and value are whitespace-trimmed; a later duplicate key wins; lines
// without '=' are ignored.
using SettingsFileValues = std::map<std::string, std::string, std::less<>>;
SettingsFileValues ParseSettingsText(std::string_view text);

// Reads and parses `path`. false (and *values untouched) when the file cannot be opened.
bool ReadSettingsFile(const std::string& path, SettingsFileValues* values);

}  // namespace asval::settings_detail
