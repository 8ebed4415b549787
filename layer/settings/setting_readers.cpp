#include "setting_readers.h"

#include <limits>
#include <optional>

#include "setting_text.h"

namespace asval::settings_detail {
namespace {

const char* TypeName(VkLayerSettingTypeEXT type) {
  switch (type) {
    case VK_LAYER_SETTING_TYPE_BOOL32_EXT:
      return "VK_LAYER_SETTING_TYPE_BOOL32_EXT";
    case VK_LAYER_SETTING_TYPE_INT32_EXT:
      return "VK_LAYER_SETTING_TYPE_INT32_EXT";
    case VK_LAYER_SETTING_TYPE_INT64_EXT:
      return "VK_LAYER_SETTING_TYPE_INT64_EXT";
    case VK_LAYER_SETTING_TYPE_UINT32_EXT:
      return "VK_LAYER_SETTING_TYPE_UINT32_EXT";
    case VK_LAYER_SETTING_TYPE_UINT64_EXT:
      return "VK_LAYER_SETTING_TYPE_UINT64_EXT";
    case VK_LAYER_SETTING_TYPE_FLOAT32_EXT:
      return "VK_LAYER_SETTING_TYPE_FLOAT32_EXT";
    case VK_LAYER_SETTING_TYPE_FLOAT64_EXT:
      return "VK_LAYER_SETTING_TYPE_FLOAT64_EXT";
    case VK_LAYER_SETTING_TYPE_STRING_EXT:
      return "VK_LAYER_SETTING_TYPE_STRING_EXT";
    default:
      return "an unknown VkLayerSettingTypeEXT";
  }
}

bool IsIntegerType(VkLayerSettingTypeEXT type) {
  return type == VK_LAYER_SETTING_TYPE_INT32_EXT || type == VK_LAYER_SETTING_TYPE_UINT32_EXT ||
         type == VK_LAYER_SETTING_TYPE_INT64_EXT || type == VK_LAYER_SETTING_TYPE_UINT64_EXT;
}

bool Fail(std::string* error, std::string message) {
  *error = std::move(message);
  return false;
}

bool WrongType(const VkLayerSettingEXT& entry, const char* expected, std::string* error) {
  return Fail(error, std::string("has type ") + TypeName(entry.type) + "; this setting takes " + expected);
}

// Common checks of an API entry that must hold exactly one value of one of the accepted types.
bool CheckSingleValue(const VkLayerSettingEXT& entry, std::string* error) {
  if (std::string problem = DescribeApiEntryProblem(entry); !problem.empty()) return Fail(error, problem);
  if (entry.valueCount != 1) {
    return Fail(error, "has valueCount " + std::to_string(entry.valueCount) + "; this setting takes one value");
  }
  return true;
}

// Value i of an integer-typed entry. nullopt for a UINT64 beyond int64_t.
std::optional<int64_t> IntegerValue(const VkLayerSettingEXT& entry, uint32_t i) {
  switch (entry.type) {
    case VK_LAYER_SETTING_TYPE_INT32_EXT:
      return static_cast<const int32_t*>(entry.pValues)[i];
    case VK_LAYER_SETTING_TYPE_UINT32_EXT:
      return static_cast<const uint32_t*>(entry.pValues)[i];
    case VK_LAYER_SETTING_TYPE_INT64_EXT:
      return static_cast<const int64_t*>(entry.pValues)[i];
    case VK_LAYER_SETTING_TYPE_UINT64_EXT: {
      const uint64_t value = static_cast<const uint64_t*>(entry.pValues)[i];
      if (value > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) return std::nullopt;
      return static_cast<int64_t>(value);
    }
    default:
      return std::nullopt;
  }
}

std::string UnsignedText(const VkLayerSettingEXT& entry, uint32_t i) {
  return entry.type == VK_LAYER_SETTING_TYPE_UINT64_EXT ? std::to_string(static_cast<const uint64_t*>(entry.pValues)[i])
                                                        : std::to_string(*IntegerValue(entry, i));
}

// The strings of a STRING entry; fails on a NULL string.
bool ApiStrings(const VkLayerSettingEXT& entry, std::vector<std::string>* out, std::string* error) {
  const char* const* strings = static_cast<const char* const*>(entry.pValues);
  std::vector<std::string> items;
  items.reserve(entry.valueCount);
  for (uint32_t i = 0; i < entry.valueCount; ++i) {
    if (strings[i] == nullptr) return Fail(error, "has a NULL string at pValues[" + std::to_string(i) + "]");
    items.emplace_back(strings[i]);
  }
  *out = std::move(items);
  return true;
}

// The first string of a STRING entry; fails when it is NULL.
bool ApiSingleString(const VkLayerSettingEXT& entry, std::string* out, std::string* error) {
  const char* text = *static_cast<const char* const*>(entry.pValues);
  if (text == nullptr) return Fail(error, "has a NULL string at pValues[0]");
  *out = text;
  return true;
}

}  // namespace

std::string DescribeApiEntryProblem(const VkLayerSettingEXT& entry) {
  if (static_cast<uint32_t>(entry.type) > static_cast<uint32_t>(VK_LAYER_SETTING_TYPE_STRING_EXT)) {
    return "has type " + std::to_string(static_cast<uint32_t>(entry.type)) +
           ", which is not a VkLayerSettingTypeEXT value";
  }
  if (entry.valueCount == 0) return "has valueCount 0";
  if (entry.pValues == nullptr) return "has pValues NULL";
  return {};
}

bool ReadBool(const RawSetting& raw, bool* out, std::string* error) {
  if (raw.api == nullptr) {
    const std::optional<bool> value = ParseBool(raw.text);
    if (!value) return Fail(error, "'" + raw.text + "' is not a boolean (true/false, on/off or an integer)");
    *out = *value;
    return true;
  }
  const VkLayerSettingEXT& entry = *raw.api;
  if (!CheckSingleValue(entry, error)) return false;
  if (entry.type == VK_LAYER_SETTING_TYPE_STRING_EXT) {
    RawSetting text;
    return ApiSingleString(entry, &text.text, error) && ReadBool(text, out, error);
  }
  if (entry.type != VK_LAYER_SETTING_TYPE_BOOL32_EXT) return WrongType(entry, "a BOOL32 (or STRING) value", error);
  const VkBool32 value = *static_cast<const VkBool32*>(entry.pValues);
  if (value != VK_TRUE && value != VK_FALSE) {
    return Fail(error, "has VkBool32 value " + std::to_string(value) + ", neither VK_TRUE nor VK_FALSE");
  }
  *out = value == VK_TRUE;
  return true;
}

bool ReadInteger(const RawSetting& raw, int64_t min, int64_t max, int64_t* out, std::string* error) {
  std::optional<int64_t> value;
  std::string shown;
  if (raw.api != nullptr && raw.api->type == VK_LAYER_SETTING_TYPE_STRING_EXT) {
    RawSetting text;
    return CheckSingleValue(*raw.api, error) && ApiSingleString(*raw.api, &text.text, error) &&
           ReadInteger(text, min, max, out, error);
  }
  if (raw.api == nullptr) {
    value = ParseInteger(raw.text);
    if (!value) return Fail(error, "'" + raw.text + "' is not an integer (decimal or 0x hexadecimal)");
    shown = raw.text;
  } else {
    const VkLayerSettingEXT& entry = *raw.api;
    if (!CheckSingleValue(entry, error)) return false;
    if (!IsIntegerType(entry.type)) return WrongType(entry, "an INT32, UINT32, INT64, UINT64 (or STRING) value", error);
    value = IntegerValue(entry, 0);
    shown = UnsignedText(entry, 0);
  }
  if (!value || *value < min || *value > max) {
    return Fail(error, shown + " is outside the range " + std::to_string(min) + ".." + std::to_string(max));
  }
  *out = *value;
  return true;
}

bool ReadString(const RawSetting& raw, std::string* out, std::string* error) {
  if (raw.api == nullptr) {
    *out = raw.text;
    return true;
  }
  const VkLayerSettingEXT& entry = *raw.api;
  if (!CheckSingleValue(entry, error)) return false;
  if (entry.type != VK_LAYER_SETTING_TYPE_STRING_EXT) return WrongType(entry, "a STRING value", error);
  return ApiSingleString(entry, out, error);
}

bool ReadList(const RawSetting& raw, std::vector<std::string>* out, std::string* error) {
  if (raw.api == nullptr) {
    *out = SplitList(raw.text);
    return true;
  }
  const VkLayerSettingEXT& entry = *raw.api;
  if (std::string problem = DescribeApiEntryProblem(entry); !problem.empty()) return Fail(error, problem);
  if (entry.type == VK_LAYER_SETTING_TYPE_STRING_EXT) return ApiStrings(entry, out, error);
  if (!IsIntegerType(entry.type)) return WrongType(entry, "STRING values (or integers)", error);
  std::vector<std::string> items;
  items.reserve(entry.valueCount);
  for (uint32_t i = 0; i < entry.valueCount; ++i) items.push_back(UnsignedText(entry, i));
  *out = std::move(items);
  return true;
}

bool ReadFlags(const RawSetting& raw, const char* setting, const FlagName* flags, size_t flag_count, uint32_t* out,
               std::string* error) {
  std::vector<std::string> names;
  if (raw.api == nullptr) {
    names = SplitList(raw.text);
  } else {
    const VkLayerSettingEXT& entry = *raw.api;
    if (std::string problem = DescribeApiEntryProblem(entry); !problem.empty()) return Fail(error, problem);
    if (entry.type != VK_LAYER_SETTING_TYPE_STRING_EXT) return WrongType(entry, "STRING values (flag names)", error);
    std::vector<std::string> values;
    if (!ApiStrings(entry, &values, error)) return false;
    // Each value may itself be a list ("error,warn"), as in the settings file: flag names never contain
    // a delimiter, so splitting is never wrong and saves apps from building one value per flag.
    for (const std::string& value : values) {
      for (std::string& name : SplitList(value)) names.push_back(std::move(name));
    }
  }
  uint32_t bits = 0;
  for (const std::string& name : names) {
    bool known = false;
    std::string valid;
    for (size_t i = 0; i < flag_count; ++i) {
      if (std::string_view(flags[i].setting) != setting) continue;
      if (name == flags[i].flag) {
        bits |= flags[i].bit;
        known = true;
      }
      valid += valid.empty() ? "" : ", ";
      valid += flags[i].flag;
    }
    if (!known) return Fail(error, "'" + name + "' is not one of its flags (" + valid + ")");
  }
  *out = bits;
  return true;
}

bool ReadEnum(const RawSetting& raw, const char* setting, const EnumValueName* values, size_t value_count,
              uint32_t* out, std::string* error) {
  std::string text = raw.text;
  if (raw.api != nullptr) {
    const VkLayerSettingEXT& entry = *raw.api;
    if (!CheckSingleValue(entry, error)) return false;
    if (entry.type != VK_LAYER_SETTING_TYPE_STRING_EXT) {
      return WrongType(entry, "one STRING value (a value name)", error);
    }
    if (!ApiSingleString(entry, &text, error)) return false;
  }
  // Trimmed like a flag name, so that "updates " from the environment reads as it does from the file.
  const std::string_view name = TrimWhitespace(text);
  std::string valid;
  for (size_t i = 0; i < value_count; ++i) {
    if (std::string_view(values[i].setting) != setting) continue;
    if (name == values[i].value) {
      *out = values[i].index;
      return true;
    }
    valid += valid.empty() ? "" : ", ";
    valid += values[i].value;
  }
  return Fail(error, "'" + std::string(name) + "' is not one of its values (" + valid + ")");
}

}  // namespace asval::settings_detail
