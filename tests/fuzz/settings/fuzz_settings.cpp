// Fuzz target: the settings library (layer/settings) on arbitrary text and arbitrary VkLayerSettingsCreateInfoEXT
// chains. One input drives, in turn:
//   1. the text helpers (setting_text.h): trimming is idempotent, a list split, written back with ',' and split
//      again, gives the same items, an integer printed in decimal parses back to itself, a boolean agrees with
//      the integer reading of the same text;
//   2. the settings file parser (settings_file.h): parse, print "key = value" lines, parse again: the same map;
//   3. LoadLayerSettings over an environment, a settings file (written to a temporary file and found through
//      VK_LAYER_SETTINGS_PATH) and an API chain with random counts, types, values, NULL pointers and cycles:
//      it never fails, it warns at least once per malformed API entry or unknown setting of this layer, and the
//      settings it returns, written as a settings file and loaded again from that file alone, are the same
//      settings, without a warning (for every setting whose value a file can spell).
// Any violated property aborts with a message naming it.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "api_settings.h"
#include "layer_settings.h"
#include "layer_settings_ext.h"
#include "setting_names.h"
#include "setting_text.h"
#include "settings_file.h"

namespace {

using namespace asval;
using namespace asval::settings_detail;

void Require(bool ok, const char* property) {
  if (!ok) {
    std::fprintf(stderr, "asval_fuzz_settings: property violated: %s\n", property);
    std::abort();
  }
}

struct Reader {
  const uint8_t* p;
  size_t n;
  uint8_t Byte() { return n ? (--n, *p++) : 0; }
  uint32_t Below(uint32_t bound) { return Byte() % bound; }
  // A string of up to `max` bytes; mostly drawn from a small alphabet of the characters the parsers treat
  // specially, so that short inputs reach their branches.
  std::string Text(size_t max) {
    const size_t length = Byte() % (max + 1);
    std::string out;
    static constexpr char kAlphabet[] = " \t,:#=\n0x1-aAfFtTrueolsn9_.\r";
    for (size_t i = 0; i < length && n; ++i) {
      const uint8_t b = Byte();
      out.push_back(b & 0x80 ? static_cast<char>(b & 0x7f) : kAlphabet[b % (sizeof(kAlphabet) - 1)]);
    }
    return out;
  }
};

// ---- the settings' names and kinds, from the generated list ----
enum class Kind { kFlags, kInt, kBool, kString, kList, kEnum };
struct SettingInfo {
  const char* name;
  Kind kind;
};
constexpr SettingInfo kSettings[] = {
#define ASVAL_SETTING_FLAGS(key, ...) {#key, Kind::kFlags},
#define ASVAL_SETTING_INT(key, ...) {#key, Kind::kInt},
#define ASVAL_SETTING_BOOL(key, ...) {#key, Kind::kBool},
#define ASVAL_SETTING_STRING(key, ...) {#key, Kind::kString},
#define ASVAL_SETTING_LIST(key, ...) {#key, Kind::kList},
#define ASVAL_SETTING_ENUM(key, ...) {#key, Kind::kEnum},
#include "asval_settings_defs.inc"
};
constexpr size_t kSettingCount = sizeof(kSettings) / sizeof(kSettings[0]);

struct NamedBit {
  const char* setting;
  const char* name;
  uint32_t value;
};
constexpr NamedBit kFlagBits[] = {
#define ASVAL_SETTING_FLAG(setting, flag, cpp_name, bit) {#setting, flag, bit},
#include "asval_settings_defs.inc"
};
constexpr NamedBit kEnumValues[] = {
#define ASVAL_SETTING_ENUM_VALUE(setting, value, cpp_name) {#setting, value, cpp_name},
#include "asval_settings_defs.inc"
};

bool KnownSetting(std::string_view name) {
  for (const SettingInfo& s : kSettings) {
    if (name == s.name) return true;
  }
  return false;
}

// ---- 1. text helpers ----
void TextProperties(const std::string& text) {
  const std::string_view trimmed = TrimWhitespace(text);
  Require(TrimWhitespace(trimmed) == trimmed, "TrimWhitespace is idempotent");
  const std::vector<std::string> items = SplitList(text);
  std::string joined;
  for (const std::string& item : items) {
    Require(!item.empty() && TrimWhitespace(item) == item, "SplitList items are trimmed and not empty");
    joined += item + ",";
  }
  Require(SplitList(joined) == items, "SplitList(join(items, ',')) == items");
  if (const std::optional<int64_t> value = ParseInteger(text)) {
    Require(ParseInteger(std::to_string(*value)) == value, "ParseInteger(to_string(v)) == v");
    Require(ParseBool(text) == (*value != 0), "ParseBool agrees with ParseInteger");
  }
  if (const std::optional<bool> flag = ParseBool(text)) {
    Require(ParseBool(*flag ? "true" : "false") == flag, "ParseBool round-trips");
  }
}

// ---- 2. the settings file parser ----
std::string PrintFile(const SettingsFileValues& values) {
  std::string text;
  for (const auto& [key, value] : values) text += key + " = " + value + "\n";
  return text;
}

void FileProperties(const std::string& text) {
  const SettingsFileValues values = ParseSettingsText(text);
  for (const auto& [key, value] : values) {
    Require(key.find_first_of("#\n=") == std::string::npos && value.find_first_of("#\n") == std::string::npos,
            "parsed keys and values hold no comment, line break (or '=' in a key)");
  }
  Require(ParseSettingsText(PrintFile(values)) == values, "ParseSettingsText(print(parsed)) == parsed");
}

// ---- 3. LoadLayerSettings ----
// What one fuzz input puts in a VkInstanceCreateInfo pNext chain; owns every string and array it points to.
struct ApiChain {
  std::vector<std::string> strings;  // reserved up front: entries point into it
  std::vector<std::vector<const char*>> string_values;
  std::vector<std::vector<uint64_t>> number_values;  // wide enough for every numeric type
  std::vector<VkLayerSettingEXT> entries;
  std::vector<VkLayerSettingsCreateInfoEXT> infos;
  VkBaseInStructure other{VK_STRUCTURE_TYPE_APPLICATION_INFO, nullptr};  // a structure of another type
  size_t expected_warnings = 0;

  const char* Keep(std::string s) {
    strings.push_back(std::move(s));
    return strings.back().c_str();
  }

  const void* Build(Reader& r) {
    strings.reserve(256);
    const uint32_t info_count = r.Below(4);
    const uint32_t entry_total = 8;
    entries.resize(entry_total);
    string_values.resize(entry_total);
    number_values.resize(entry_total);
    infos.resize(info_count);
    uint32_t next_entry = 0;
    for (uint32_t k = 0; k < info_count; ++k) {
      VkLayerSettingsCreateInfoEXT& info = infos[k];
      info = VkLayerSettingsCreateInfoEXT{VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT, nullptr, 0, nullptr};
      const uint32_t count = r.Below(entry_total - next_entry + 1);
      info.settingCount = count;
      if (count > 0 && r.Below(8) == 0) {
        expected_warnings += 1;  // settingCount without pSettings: one warning, the structure ignored
        continue;
      }
      info.pSettings = count ? &entries[next_entry] : (r.Below(2) ? nullptr : entries.data());
      for (uint32_t i = 0; i < count; ++i) Entry(r, next_entry++);
    }
    // Chain: the create infos in order, another structure between them now and then, and rarely a cycle.
    const void* head = nullptr;
    const bool cycle = info_count > 0 && r.Below(32) == 0;
    for (uint32_t k = info_count; k-- > 0;) {
      infos[k].pNext = head;
      head = &infos[k];
      if (k == 1 && r.Below(2)) {
        other.pNext = static_cast<const VkBaseInStructure*>(head);
        head = &other;
      }
    }
    if (cycle) {
      infos[info_count - 1].pNext = head;  // the last points back at the first: the walk must stop
      expected_warnings = 1;  // at least the cycle's; each entry is then seen many times
    }
    return head;
  }

  void Entry(Reader& r, uint32_t at) {
    VkLayerSettingEXT& e = entries[at];
    const uint32_t layer = r.Below(8);
    e.pLayerName = layer == 0 ? nullptr : layer == 1 ? "VK_LAYER_KHRONOS_validation" : kLayerName;
    const uint32_t name = r.Below(kSettingCount + 3);
    e.pSettingName = name < kSettingCount ? kSettings[name].name
                     : name == kSettingCount ? nullptr
                                             : Keep(r.Text(12));
    e.type = static_cast<VkLayerSettingTypeEXT>(r.Below(10));
    e.valueCount = r.Below(4);
    const bool null_values = r.Below(8) == 0;
    if (e.type == VK_LAYER_SETTING_TYPE_STRING_EXT) {
      for (uint32_t i = 0; i < e.valueCount; ++i) {
        string_values[at].push_back(r.Below(16) == 0 ? nullptr : Keep(r.Text(24)));
      }
      e.pValues = null_values || e.valueCount == 0 ? nullptr : string_values[at].data();
    } else {
      for (uint32_t i = 0; i < e.valueCount; ++i) {
        uint64_t v = 0;
        for (int b = 0; b < 8; ++b) v = v << 8 | r.Byte();
        if (r.Below(2)) v %= 4;  // small values (VK_TRUE, VK_FALSE, enum indices) often
        number_values[at].push_back(v);
      }
      // Values are read with the entry's element type; 32-bit types read the first words.
      e.pValues = null_values || e.valueCount == 0 ? nullptr : number_values[at].data();
    }
    // Warnings owed whatever the other sources say: every entry of this layer is checked.
    if (e.pLayerName == nullptr) {
      ++expected_warnings;
    } else if (e.pLayerName == kLayerName) {
      if (e.pSettingName == nullptr || !KnownSetting(e.pSettingName)) {
        ++expected_warnings;
      } else if (static_cast<uint32_t>(e.type) > VK_LAYER_SETTING_TYPE_STRING_EXT || e.valueCount == 0 ||
                 e.pValues == nullptr) {
        ++expected_warnings;
      }
    }
  }
};

// One settings file per process, rewritten for each input (twice) and removed at exit: in /dev/shm where there is
// one (a write there costs microseconds; on a disk-backed /tmp about a millisecond).
struct TempPath {
  std::string path = std::string(access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp") + "/asval_fuzz_settings_" +
                     std::to_string(getpid()) + ".txt";
  ~TempPath() { std::remove(path.c_str()); }
};
const std::string& TempFile() {
  static const TempPath temp;
  return temp.path;
}

void WriteFile(const std::string& text) {
  std::ofstream file(TempFile(), std::ios::binary | std::ios::trunc);
  file << text;
}

// Sources: only the given variables, and the settings file at TempFile() through VK_LAYER_SETTINGS_PATH.
SettingsSources Sources(std::map<std::string, std::string> env) {
  env["VK_LAYER_SETTINGS_PATH"] = TempFile();
  SettingsSources sources;
  sources.getenv = [env = std::move(env)](const char* name) {
    const auto it = env.find(name);
    return it == env.end() ? std::string() : it->second;
  };
  sources.cwd = "/nonexistent-asval-fuzz";
  return sources;
}

// A string a settings file can spell: not empty (empty means unset), no comment or line break, nothing trimmed.
bool Spellable(const std::string& s) {
  return !s.empty() && s.find_first_of("#\n") == std::string::npos && TrimWhitespace(s) == s;
}

// The settings written as a settings file. *same: the fields a file cannot spell, to be copied over before the
// comparison.
std::string PrintSettings(const LayerSettings& s, std::vector<std::string>* unspellable) {
  const std::string prefix = FileKeyPrefix(kLayerName);
  std::string text;
  const auto line = [&](const char* key, const std::string& value) { text += prefix + key + " = " + value + "\n"; };
  const auto flags = [&](const char* key, uint32_t bits) {
    std::string value;
    for (const NamedBit& f : kFlagBits) {
      if (std::string_view(f.setting) == key && (bits & f.value)) value += std::string(f.name) + ",";
    }
    line(key, value.empty() ? "," : value);  // "," is an empty list, where an empty value would be unset
  };
  const auto enumeration = [&](const char* key, uint32_t index) {
    for (const NamedBit& v : kEnumValues) {
      if (std::string_view(v.setting) == key && v.value == index) line(key, v.name);
    }
  };
  const auto list = [&](const char* key, const std::vector<std::string>& items) {
    std::string value;
    bool ok = true;
    for (const std::string& item : items) {
      ok = ok && Spellable(item) && item.find(',') == std::string::npos;
      value += item + ",";
    }
    if (!ok) unspellable->push_back(key);
    line(key, value.empty() ? "," : value);
  };
  const auto string = [&](const char* key, const std::string& value, const std::string& fallback) {
    if (value.empty() && fallback.empty()) return;  // unset reads as the (empty) default
    if (!Spellable(value)) unspellable->push_back(key);
    line(key, value);
  };
  const LayerSettings defaults;
#define ASVAL_SETTING_FLAGS(key, ...) flags(#key, s.key);
#define ASVAL_SETTING_INT(key, ...) line(#key, std::to_string(s.key));
#define ASVAL_SETTING_BOOL(key, ...) line(#key, s.key ? "true" : "false");
#define ASVAL_SETTING_STRING(key, ...) string(#key, s.key, defaults.key);
#define ASVAL_SETTING_LIST(key, ...) list(#key, s.key);
#define ASVAL_SETTING_ENUM(key, ...) enumeration(#key, static_cast<uint32_t>(s.key));
#include "asval_settings_defs.inc"
  return text;
}

void CopyField(const std::string& name, const LayerSettings& from, LayerSettings* to) {
#define ASVAL_SETTING_STRING(key, ...) \
  if (name == #key) to->key = from.key;
#define ASVAL_SETTING_LIST(key, ...) \
  if (name == #key) to->key = from.key;
#include "asval_settings_defs.inc"
}

void LoadProperties(Reader& r) {
  // Environment: a few settings through one of their three variable names.
  std::map<std::string, std::string> env;
  const uint32_t env_count = r.Below(3);
  for (uint32_t i = 0; i < env_count; ++i) {
    const SettingInfo& s = kSettings[r.Below(kSettingCount)];
    env[EnvSettingNames(kLayerName, s.name)[r.Below(3)]] = r.Text(20);
  }
  // Settings file: lines of known keys, unknown keys of this layer, other layers' keys, and noise.
  std::string file;
  size_t unknown_keys = 0;
  std::map<std::string, bool> seen_unknown;
  const uint32_t lines = r.Below(6);
  for (uint32_t i = 0; i < lines; ++i) {
    const uint32_t what = r.Below(kSettingCount + 3);
    if (what < kSettingCount) {
      file += FileSettingKey(kLayerName, kSettings[what].name) + " =" + r.Text(20) + "\n";
    } else if (what == kSettingCount) {
      const std::string name = "zz" + r.Text(6);
      const std::string key = FileSettingKey(kLayerName, name);
      // An unknown key of this layer, when the line survives as written (no comment or break inside).
      if (key.find_first_of("#\n=") == std::string::npos && TrimWhitespace(key) == key && !seen_unknown[key]) {
        seen_unknown[key] = true;
        ++unknown_keys;
      }
      file += key + "=1\n";
    } else {
      file += r.Text(30) + "\n";
    }
  }
  WriteFile(file);
  ApiChain chain;
  const void* pnext = chain.Build(r);

  std::vector<std::string> warnings;
  const LayerSettings settings = LoadLayerSettings(Sources(env), pnext, &warnings);
  Require(warnings.size() >= chain.expected_warnings + unknown_keys,
          "a warning for every malformed API entry, unknown API setting and unknown file key of this layer");
  for (const std::string& w : warnings) Require(w.rfind("asval settings: ", 0) == 0, "warnings are prefixed");

  // Round trip through a settings file alone.
  std::vector<std::string> unspellable;
  WriteFile(PrintSettings(settings, &unspellable));
  std::vector<std::string> again_warnings;
  LayerSettings again = LoadLayerSettings(Sources({}), nullptr, &again_warnings);
  for (const std::string& name : unspellable) CopyField(name, settings, &again);
  if (unspellable.empty() && !again_warnings.empty()) {
    std::fprintf(stderr, "%s\n", again_warnings.front().c_str());
  }
  Require(unspellable.empty() ? again_warnings.empty() : true, "settings written as a file load without warnings");
  Require(again == settings, "settings written as a file load back as the same settings");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Reader r{data, size};
  const std::string text = r.Text(64);
  TextProperties(text);
  FileProperties(r.Text(255) + text);
  LoadProperties(r);
  return 0;
}
