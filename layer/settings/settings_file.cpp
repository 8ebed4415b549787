#include "settings_file.h"

#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include "setting_text.h"

namespace asval::settings_detail {
namespace {

constexpr const char kFileName[] = "vk_layer_settings.txt";

}  // namespace

std::string EnvValue(const SettingsSources& sources, const char* name) {
  return sources.getenv ? sources.getenv(name) : std::string();
}

SettingsFileLocation FindSettingsFile(const SettingsSources& sources) {
  struct stat info {};

  // 1. The file vkconfig writes.
  std::string data_home = EnvValue(sources, "XDG_DATA_HOME");
  if (data_home.empty()) {
    const std::string home = EnvValue(sources, "HOME");
    if (!home.empty()) data_home = home + "/.local/share";
  }
  if (!data_home.empty()) {
    std::string vkconfig_file = data_home + "/vulkan/settings.d/" + kFileName;
    if (stat(vkconfig_file.c_str(), &info) == 0 && S_ISREG(info.st_mode)) {
      return {std::move(vkconfig_file), SettingsFileLocation::Origin::kVkconfig};
    }
  }

  // 2. VK_LAYER_SETTINGS_PATH: a file, or a directory holding the file. A missing path is skipped.
  std::string env_path = EnvValue(sources, "VK_LAYER_SETTINGS_PATH");
  if (!env_path.empty() && stat(env_path.c_str(), &info) == 0) {
    if (S_ISDIR(info.st_mode)) env_path.append("/").append(kFileName);
    return {std::move(env_path), SettingsFileLocation::Origin::kLayerSettingsPath};
  }

  // 3. The working directory.
  std::string cwd_file = sources.cwd.empty() ? std::string(kFileName) : sources.cwd + "/" + kFileName;
  return {std::move(cwd_file), SettingsFileLocation::Origin::kWorkingDirectory};
}

SettingsFileValues ParseSettingsText(std::string_view text) {
  SettingsFileValues values;
  size_t line_start = 0;
  while (line_start < text.size()) {
    size_t line_end = text.find('\n', line_start);
    if (line_end == std::string_view::npos) line_end = text.size();
    std::string_view line = text.substr(line_start, line_end - line_start);
    line_start = line_end + 1;

    line = line.substr(0, line.find('#'));
    const size_t equals = line.find('=');
    if (equals == std::string_view::npos) continue;
    const std::string_view key = TrimWhitespace(line.substr(0, equals));
    const std::string_view value = TrimWhitespace(line.substr(equals + 1));
    values.insert_or_assign(std::string(key), std::string(value));
  }
  return values;
}

bool ReadSettingsFile(const std::string& path, SettingsFileValues* values) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return false;
  std::ostringstream contents;
  contents << file.rdbuf();
  *values = ParseSettingsText(contents.str());
  return true;
}

}  // namespace asval::settings_detail
