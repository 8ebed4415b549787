// Turning one raw setting value, from text (environment or file) or from a VkLayerSettingEXT, into a
// typed value. Each reader writes its output only on success; on failure it explains why in *error.
//
// API value types accepted per setting kind (anything else is a "wrong type" error):
//   BOOL          VK_LAYER_SETTING_TYPE_BOOL32_EXT, one value, VK_TRUE or VK_FALSE
//   INT           INT32, UINT32, INT64 or UINT64, one value, within the setting's range
//   STRING        STRING, one non-null value, taken verbatim
//   LIST          STRING (each value one item, verbatim), or INT32/UINT32/INT64/UINT64 written in
//                 decimal, as VUL converts them for string lists
//   FLAGS         STRING, each value one flag name
//   ENUM          STRING, one value, the name of one of its values
// Beyond VUL (which rejects a type mismatch), BOOL and INT also take one STRING value parsed like
// text, so an application can pass every setting as a string, as it would write it in the file.
// Text values: BOOL and INT per setting_text.h; STRING verbatim (never split: it may be a path with
// ':'); LIST and FLAGS split per SplitList; ENUM whitespace-trimmed, never split. FLAGS and ENUM names
// are case-sensitive, as in vkconfig's manifest.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "layer_settings_ext.h"

namespace asval::settings_detail {

// One value as found in the winning source: either text or an API entry.
struct RawSetting {
  std::string origin;                      // for messages, e.g. "environment variable VK_..."
  std::string text;                        // environment or file value, when api is null
  const VkLayerSettingEXT* api = nullptr;  // the VkLayerSettingsCreateInfoEXT entry otherwise
};

// Name and bit of one flag of a FLAGS setting.
struct FlagName {
  const char* setting;
  const char* flag;
  uint32_t bit;
};

bool ReadBool(const RawSetting& raw, bool* out, std::string* error);
bool ReadInteger(const RawSetting& raw, int64_t min, int64_t max, int64_t* out, std::string* error);
bool ReadString(const RawSetting& raw, std::string* out, std::string* error);
bool ReadList(const RawSetting& raw, std::vector<std::string>* out, std::string* error);
// `flags` lists every flag of every setting; only those whose .setting equals `setting` apply.
bool ReadFlags(const RawSetting& raw, const char* setting, const FlagName* flags, size_t flag_count, uint32_t* out,
               std::string* error);

// Name and index of one value of an ENUM setting.
struct EnumValueName {
  const char* setting;
  const char* value;
  uint32_t index;
};

// `values` lists every value of every ENUM setting; only those whose .setting equals `setting` apply.
bool ReadEnum(const RawSetting& raw, const char* setting, const EnumValueName* values, size_t value_count,
              uint32_t* out, std::string* error);

// Checks pValues/valueCount/type of an API entry without interpreting it; "" when usable.
std::string DescribeApiEntryProblem(const VkLayerSettingEXT& entry);

// Same for integer outputs narrower than int64_t: reads, range-checks against [min, max], converts.
template <typename Int>
bool ReadIntegerAs(const RawSetting& raw, int64_t min, int64_t max, Int* out, std::string* error) {
  int64_t value = 0;
  if (!ReadInteger(raw, min, max, &value, error)) return false;
  *out = static_cast<Int>(value);
  return true;
}

// Same for the generated enum type of one ENUM setting.
template <typename Enum>
bool ReadEnumAs(const RawSetting& raw, const char* setting, const EnumValueName* values, size_t value_count,
                Enum* out, std::string* error) {
  uint32_t index = 0;
  if (!ReadEnum(raw, setting, values, value_count, &index, error)) return false;
  *out = static_cast<Enum>(index);
  return true;
}

}  // namespace asval::settings_detail
