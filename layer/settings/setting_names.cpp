#include "setting_names.h"

#include <cctype>

namespace asval::settings_detail {
namespace {

constexpr std::string_view kLayerPrefix = "VK_LAYER_";

std::string_view TrimPrefix(std::string_view layer_name) {
  if (layer_name.substr(0, kLayerPrefix.size()) == kLayerPrefix) layer_name.remove_prefix(kLayerPrefix.size());
  return layer_name;
}

// Drops the vendor part: "ASVAL_as_validation" -> "as_validation".
std::string_view TrimVendor(std::string_view layer_name) {
  const std::string_view body = TrimPrefix(layer_name);
  const size_t separator = body.find('_');
  return separator == std::string_view::npos ? body : body.substr(separator + 1);
}

std::string Upper(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string Lower(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

std::string FileKeyPrefix(std::string_view layer_name) { return Lower(TrimPrefix(layer_name)) + "."; }

std::string FileSettingKey(std::string_view layer_name, std::string_view setting) {
  return FileKeyPrefix(layer_name).append(setting);
}

std::array<std::string, 3> EnvSettingNames(std::string_view layer_name, std::string_view setting) {
  const std::string upper_setting = Upper(setting);
  return {
      "VK_" + Upper(TrimPrefix(layer_name)) + "_" + upper_setting,
      "VK_" + Upper(TrimVendor(layer_name)) + "_" + upper_setting,
      "VK_" + upper_setting,
  };
}

}  // namespace asval::settings_detail
