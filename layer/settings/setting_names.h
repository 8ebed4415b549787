// How a setting is named outside the code, following Vulkan-Utility-Libraries' layer_settings_util.cpp
// (GetFileSettingName, GetEnvSettingName): "VK_LAYER_ASVAL_as_validation" + "duplicate_message_limit" gives
//   file key      asval_as_validation.duplicate_message_limit   (prefix lower-cased, setting as is)
//   environment   VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT, VK_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT,
//                 VK_DUPLICATE_MESSAGE_LIMIT                      (in lookup order, all upper-cased)
#pragma once

#include <array>
#include <string>
#include <string_view>

namespace asval::settings_detail {

// "asval_as_validation." for kLayerName: the prefix every file key of this layer starts with.
std::string FileKeyPrefix(std::string_view layer_name);

// FileKeyPrefix + setting.
std::string FileSettingKey(std::string_view layer_name, std::string_view setting);

// The three environment variable names, in the order they are tried (TRIM_NONE, TRIM_VENDOR, TRIM_NAMESPACE).
std::array<std::string, 3> EnvSettingNames(std::string_view layer_name, std::string_view setting);

}  // namespace asval::settings_detail
