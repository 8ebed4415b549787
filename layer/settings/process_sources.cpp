// The real process environment behind SettingsSources, and the convenience overload that uses it.
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "layer_settings.h"

namespace asval {

SettingsSources SettingsSources::FromProcess() {
  SettingsSources sources;
  sources.getenv = [](const char* name) {
    const char* value = std::getenv(name);
    return value == nullptr ? std::string() : std::string(value);
  };
  std::error_code error;
  const std::filesystem::path cwd = std::filesystem::current_path(error);
  if (!error) sources.cwd = cwd.string();
  return sources;
}

LayerSettings LoadLayerSettings(const void* instance_create_info_pnext, std::vector<std::string>* warnings) {
  return LoadLayerSettings(SettingsSources::FromProcess(), instance_create_info_pnext, warnings);
}

}  // namespace asval
