// Parsing of setting values written as text (environment variables, vk_layer_settings.txt), following
// Vulkan-Utility-Libraries (layer_settings_util.cpp, vk_layer_settings.cpp) with two documented
// leniencies: list items are whitespace-trimmed and empty items dropped, and integers must be
// well-formed as a whole (VUL's atoi would read "12abc" as 12 and "0x10" as 0).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace asval::settings_detail {

// Strips " \t\f\v\n\r" from both ends, like VUL's TrimWhitespace.
std::string_view TrimWhitespace(std::string_view text);

// Splits on ',' when the text has one, otherwise on ':' (VUL FindDelimiter on Linux).
std::vector<std::string> SplitList(std::string_view text);

// Optional '-', then decimal digits or 0x/0X and hex digits. Surrounding whitespace is ignored.
// nullopt when malformed or outside int64_t.
std::optional<int64_t> ParseInteger(std::string_view text);

// true/false, on/off (any case), or an integer (non-zero = true). nullopt when none of these.
std::optional<bool> ParseBool(std::string_view text);

}  // namespace asval::settings_detail
