// VkLayerSettingsCreateInfoEXT: every VkLayerSettingTypeEXT, chains, first match, malformed structures.
#include <catch2/catch_test_macros.hpp>

#include "settings_test_support.h"

using namespace asval;
using asval::test::CreateInfo;
using asval::test::Entry;
using asval::test::FakeSources;
using asval::test::HasWarning;
using Items = std::vector<std::string>;

namespace {

LayerSettings LoadApi(const void* pNext, std::vector<std::string>* warnings) {
  FakeSources fake;
  return LoadLayerSettings(fake.Get(), pNext, warnings);
}

LayerSettings LoadOne(const VkLayerSettingEXT& entry, std::vector<std::string>* warnings) {
  const std::vector<VkLayerSettingEXT> entries = {entry};
  const VkLayerSettingsCreateInfoEXT info = CreateInfo(entries);
  return LoadApi(&info, warnings);
}

}  // namespace

TEST_CASE("API values of each accepted type", "[settings][api]") {
  std::vector<std::string> warnings;
  const VkBool32 yes = VK_TRUE;
  CHECK(LoadOne(Entry("log_to_stderr", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &yes), &warnings).log_to_stderr);

  const int32_t i32 = 5;
  const int64_t i64 = 6;
  const uint32_t u32 = 7;
  const uint64_t u64 = 8;
  CHECK(LoadOne(Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_INT32_EXT, 1, &i32), &warnings)
            .duplicate_message_limit == 5);
  CHECK(LoadOne(Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_INT64_EXT, 1, &i64), &warnings)
            .duplicate_message_limit == 6);
  CHECK(LoadOne(Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &u32), &warnings)
            .duplicate_message_limit == 7);
  CHECK(LoadOne(Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT64_EXT, 1, &u64), &warnings)
            .duplicate_message_limit == 8);

  const char* path = "/tmp/report:1.jsonl";
  CHECK(LoadOne(Entry("report_file", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &path), &warnings).report_file ==
        "/tmp/report:1.jsonl");

  // BOOL and INT settings also take one string, parsed like a settings-file value.
  const char* on = "on";
  const char* hex = "0x11";
  CHECK(LoadOne(Entry("log_to_stderr", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &on), &warnings).log_to_stderr);
  CHECK(LoadOne(Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &hex), &warnings)
            .duplicate_message_limit == 17);

  const char* flags[] = {"warn", "info"};
  CHECK(LoadOne(Entry("report_flags", VK_LAYER_SETTING_TYPE_STRING_EXT, 2, flags), &warnings).report_flags ==
        (kSeverityWarn | kSeverityInfo));

  const char* capture = "all";
  CHECK(LoadOne(Entry("capture", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &capture), &warnings).capture == kCaptureAll);
  const uint32_t budget = 1024;
  CHECK(LoadOne(Entry("capture_budget_mb", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &budget), &warnings)
            .capture_budget_mb == 1024);

  const char* filters[] = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710", "03667"};
  CHECK(
      LoadOne(Entry("message_id_filter", VK_LAYER_SETTING_TYPE_STRING_EXT, 2, filters), &warnings).message_id_filter ==
      Items{filters[0], filters[1]});
  // Hashes passed as integers become decimal strings, as VUL converts them for string lists.
  const uint32_t hashes[] = {0xDEADBEEFu, 12};
  CHECK(LoadOne(Entry("message_id_filter", VK_LAYER_SETTING_TYPE_UINT32_EXT, 2, hashes), &warnings).message_id_filter ==
        Items{"3735928559", "12"});
  const int64_t signed_hashes[] = {-1};
  CHECK(LoadOne(Entry("message_id_filter", VK_LAYER_SETTING_TYPE_INT64_EXT, 1, signed_hashes), &warnings)
            .message_id_filter == Items{"-1"});
  CHECK(warnings.empty());
}

TEST_CASE("API values of a wrong type give a warning and keep the default", "[settings][api][malformed]") {
  const float f32 = 1.0f;
  const double f64 = 1.0;
  const VkBool32 yes = VK_TRUE;
  const uint32_t one = 1;
  struct Case {
    VkLayerSettingEXT entry;
    const char* expect;
  };
  for (const Case& c : {
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_FLOAT32_EXT, 1, &f32),
                "VK_LAYER_SETTING_TYPE_FLOAT32_EXT"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &yes),
                "VK_LAYER_SETTING_TYPE_BOOL32_EXT"},
           Case{Entry("log_to_stderr", VK_LAYER_SETTING_TYPE_FLOAT64_EXT, 1, &f64),
                "VK_LAYER_SETTING_TYPE_FLOAT64_EXT"},
           Case{Entry("log_to_stderr", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &one), "VK_LAYER_SETTING_TYPE_UINT32_EXT"},
           Case{Entry("report_file", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &one), "VK_LAYER_SETTING_TYPE_UINT32_EXT"},
           Case{Entry("report_flags", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &one), "VK_LAYER_SETTING_TYPE_UINT32_EXT"},
           Case{Entry("message_id_filter", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &yes),
                "VK_LAYER_SETTING_TYPE_BOOL32_EXT"},
           // An ENUM takes its value name as a string, never an index.
           Case{Entry("capture", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &one), "VK_LAYER_SETTING_TYPE_UINT32_EXT"},
           Case{Entry("capture", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &yes), "VK_LAYER_SETTING_TYPE_BOOL32_EXT"},
       }) {
    CAPTURE(c.entry.pSettingName, c.expect);
    std::vector<std::string> warnings;
    CHECK(LoadOne(c.entry, &warnings) == LayerSettings{});
    REQUIRE(warnings.size() == 1);
    CHECK(HasWarning(warnings, "VkLayerSettingsCreateInfoEXT #0 pSettings[0]", c.entry.pSettingName, c.expect,
                     "the entry is ignored"));
  }
}

TEST_CASE("malformed API entries give a warning and are ignored", "[settings][api][malformed]") {
  const uint32_t two_values[] = {1, 2};
  const VkBool32 not_a_bool = 2;
  const int32_t negative = -1;
  const uint64_t huge = 1ull << 40;
  const char* null_string[] = {"error", nullptr};
  const char* maybe = "maybe";
  const char* many = "many";
  const char* minus = "-3";
  const char* capture_names[] = {"off", "all"};
  const char* upper_all = "ALL";
  const uint32_t no_budget = 0;
  struct Case {
    VkLayerSettingEXT entry;
    const char* expect;
  };
  for (const Case& c : {
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 0, two_values), "valueCount 0"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, nullptr), "pValues NULL"},
           Case{Entry("duplicate_message_limit", static_cast<VkLayerSettingTypeEXT>(99), 1, two_values),
                "type 99, which is not a VkLayerSettingTypeEXT"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 2, two_values),
                "valueCount 2; this setting takes one value"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_INT32_EXT, 1, &negative),
                "-1 is outside the range"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT64_EXT, 1, &huge),
                "1099511627776 is outside the range"},
           Case{Entry("log_to_stderr", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &not_a_bool),
                "neither VK_TRUE nor VK_FALSE"},
           Case{Entry("log_to_stderr", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &maybe), "'maybe' is not a boolean"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &many),
                "'many' is not an integer"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &minus),
                "-3 is outside the range"},
           Case{Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_STRING_EXT, 2, null_string),
                "valueCount 2; this setting takes one value"},
           Case{Entry("report_file", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &null_string[1]),
                "NULL string at pValues[0]"},
           Case{Entry("report_flags", VK_LAYER_SETTING_TYPE_STRING_EXT, 2, null_string), "NULL string at pValues[1]"},
           Case{Entry("message_id_filter", VK_LAYER_SETTING_TYPE_STRING_EXT, 2, null_string),
                "NULL string at pValues[1]"},
           Case{Entry("message_id_filter", VK_LAYER_SETTING_TYPE_STRING_EXT, 0, nullptr), "valueCount 0"},
           Case{Entry("capture", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &upper_all), "'ALL' is not one of its values"},
           Case{Entry("capture", VK_LAYER_SETTING_TYPE_STRING_EXT, 2, capture_names),
                "valueCount 2; this setting takes one value"},
           Case{Entry("capture", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &null_string[1]), "NULL string at pValues[0]"},
           Case{Entry("capture_budget_mb", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &no_budget),
                "0 is outside the range 1..65536"},
           Case{Entry("no_such_setting", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, two_values),
                "unknown setting 'no_such_setting' for VK_LAYER_ASVAL_as_validation"},
       }) {
    CAPTURE(c.expect);
    std::vector<std::string> warnings;
    CHECK(LoadOne(c.entry, &warnings) == LayerSettings{});
    REQUIRE(warnings.size() == 1);
    CHECK(HasWarning(warnings, "VkLayerSettingsCreateInfoEXT #0 pSettings[0]", c.expect, "ignored"));
  }
}

TEST_CASE("malformed API structures give a warning, never a crash", "[settings][api][malformed]") {
  const uint32_t five = 5;
  std::vector<std::string> warnings;

  const VkLayerSettingsCreateInfoEXT no_array{VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT, nullptr, 3, nullptr};
  CHECK(LoadApi(&no_array, &warnings) == LayerSettings{});
  CHECK(HasWarning(warnings, "settingCount 3 but pSettings NULL"));

  warnings.clear();
  const std::vector<VkLayerSettingEXT> entries = {
      VkLayerSettingEXT{nullptr, "duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &five},
      VkLayerSettingEXT{kLayerName, nullptr, VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &five},
      VkLayerSettingEXT{"VK_LAYER_OTHER_layer", nullptr, VK_LAYER_SETTING_TYPE_UINT32_EXT, 0,
                        nullptr},  // not ours: silent
  };
  const VkLayerSettingsCreateInfoEXT info = CreateInfo(entries);
  CHECK(LoadApi(&info, &warnings) == LayerSettings{});
  CHECK(warnings.size() == 2);
  CHECK(HasWarning(warnings, "pSettings[0] has pLayerName NULL"));
  CHECK(HasWarning(warnings, "pSettings[1] has pSettingName NULL"));

  warnings.clear();
  VkBaseInStructure loop{VK_STRUCTURE_TYPE_APPLICATION_INFO, nullptr};
  loop.pNext = &loop;  // a cyclic chain ends after a bounded walk
  CHECK(LoadApi(&loop, &warnings) == LayerSettings{});
  CHECK(HasWarning(warnings, "a cycle?"));
}

TEST_CASE("all structures of the chain are searched; the first usable entry wins", "[settings][api]") {
  const uint32_t first = 1, second = 2, other_layer = 99;
  const uint32_t empty[] = {0};
  const std::vector<VkLayerSettingEXT> tail_entries = {
      Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &second),
      Entry("report_flags", VK_LAYER_SETTING_TYPE_STRING_EXT, 0, empty),  // malformed: ignored
  };
  const char* info_only[] = {"info"};
  const std::vector<VkLayerSettingEXT> more_tail = {
      Entry("report_flags", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, info_only),
  };
  const VkLayerSettingsCreateInfoEXT third = CreateInfo(more_tail);
  const VkLayerSettingsCreateInfoEXT second_info = CreateInfo(tail_entries, &third);
  // Another structure type between them is skipped.
  VkApplicationInfo unrelated{};
  unrelated.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  unrelated.pNext = &second_info;
  const std::vector<VkLayerSettingEXT> head_entries = {
      VkLayerSettingEXT{"VK_LAYER_KHRONOS_validation", "duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1,
                        &other_layer},
      Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &first),
  };
  const VkLayerSettingsCreateInfoEXT head = CreateInfo(head_entries, &unrelated);

  std::vector<std::string> warnings;
  const LayerSettings s = LoadApi(&head, &warnings);
  CHECK(s.duplicate_message_limit == 1);   // first of ours, other layers' entries skipped
  CHECK(s.report_flags == kSeverityInfo);  // the malformed earlier entry does not block a later one
  REQUIRE(warnings.size() == 1);
  CHECK(HasWarning(warnings, "VkLayerSettingsCreateInfoEXT #1 pSettings[1] (report_flags): has valueCount 0"));

  // Without our first entry the second structure's applies.
  const std::vector<VkLayerSettingEXT> only_other = {head_entries[0]};
  const VkLayerSettingsCreateInfoEXT head2 = CreateInfo(only_other, &unrelated);
  CHECK(LoadApi(&head2, nullptr).duplicate_message_limit == 2);
}

TEST_CASE("API entries are checked even when the environment overrides them", "[settings][api][malformed]") {
  FakeSources fake;
  fake.env["VK_DUPLICATE_MESSAGE_LIMIT"] = "3";
  const float wrong = 1.0f;
  const std::vector<VkLayerSettingEXT> entries = {
      Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_FLOAT32_EXT, 1, &wrong)};
  const VkLayerSettingsCreateInfoEXT info = CreateInfo(entries);
  std::vector<std::string> warnings;
  CHECK(LoadLayerSettings(fake.Get(), &info, &warnings).duplicate_message_limit == 3);
  CHECK(HasWarning(warnings, "FLOAT32"));
}
