// Defaults: the values the task defines, the .inc's typed defaults against its default texts, and the
// checked-in vk_layer_settings.txt against both.
#include <catch2/catch_test_macros.hpp>

#include <fstream>
#include <regex>
#include <sstream>
#include <type_traits>

#include "settings_file.h"
#include "settings_test_support.h"

using namespace asval;
using asval::test::FakeSources;
using asval::test::WriteFile;

namespace {

struct DefaultText {
  const char* key;
  const char* text;
};

// Every setting with its default spelled as a settings file spells it, from the .inc.
constexpr DefaultText kDefaultTexts[] = {
#define ASVAL_SETTING_FLAGS(key, default_bits, default_text) {#key, default_text},
#define ASVAL_SETTING_INT(key, cpp_type, default_value, min, max, default_text) {#key, default_text},
#define ASVAL_SETTING_BOOL(key, default_value, default_text) {#key, default_text},
#define ASVAL_SETTING_STRING(key, default_value, default_text) {#key, default_text},
#define ASVAL_SETTING_LIST(key, default_value, default_text) {#key, default_text},
#define ASVAL_SETTING_ENUM(key, cpp_type, default_value, default_text) {#key, default_text},
#include "asval_settings_defs.inc"
};

LayerSettings LoadFile(const std::string& text, std::vector<std::string>* warnings) {
  FakeSources fake;
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", text);
  return LoadLayerSettings(fake.Get(), nullptr, warnings);
}

std::string ReadRepoSample() {
  std::ifstream file(std::string(ASVAL_SOURCE_DIR) + "/vk_layer_settings.txt");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("default values are the ones the layer documents", "[settings][defaults]") {
  const LayerSettings s;
  CHECK(s.report_flags == (kSeverityError | kSeverityWarn));
  CHECK(s.capture == kCaptureUpdates);
  CHECK(s.capture_budget_mb == 256u);
  CHECK(s.duplicate_message_limit == 10u);
  CHECK(s.message_id_filter.empty());
  CHECK(s.report_file.empty());
  CHECK_FALSE(s.log_to_stderr);
  CHECK(kSeverityError == 1u);
  CHECK(kSeverityWarn == 2u);
  CHECK(kSeverityInfo == 4u);
  // ENUM settings have their own type, its enumerators numbered in the manifest's order.
  STATIC_CHECK(std::is_same_v<decltype(s.capture), CaptureMode>);
  CHECK(kCaptureOff == 0u);
  CHECK(kCaptureUpdates == 1u);
  CHECK(kCaptureAll == 2u);
}

TEST_CASE("each default text reads back as the typed default", "[settings][defaults]") {
  for (const DefaultText& d : kDefaultTexts) {
    CAPTURE(d.key, d.text);
    std::vector<std::string> warnings;
    CHECK(LoadFile("asval_as_validation." + std::string(d.key) + " = " + d.text + "\n", &warnings) == LayerSettings{});
    CHECK(warnings.empty());
  }
  // And a non-default value really changes something, so the comparison above can fail.
  CHECK(LoadFile("asval_as_validation.report_flags = error\n", nullptr) != LayerSettings{});
}

TEST_CASE("the repository's vk_layer_settings.txt documents every setting with its default", "[settings][defaults]") {
  const std::string sample = ReadRepoSample();
  REQUIRE_FALSE(sample.empty());

  // As checked in, every setting line is commented out: the file changes nothing.
  std::vector<std::string> warnings;
  CHECK(settings_detail::ParseSettingsText(sample).empty());
  CHECK(LoadFile(sample, &warnings) == LayerSettings{});
  CHECK(warnings.empty());

  // Uncommented, it sets every setting to its default.
  const std::string active =
      std::regex_replace(sample, std::regex("(^|\n)#asval_as_validation\\."), "$1asval_as_validation.");
  const settings_detail::SettingsFileValues values = settings_detail::ParseSettingsText(active);
  CHECK(values.size() == std::size(kDefaultTexts));
  for (const DefaultText& d : kDefaultTexts) {
    CAPTURE(d.key);
    const auto it = values.find("asval_as_validation." + std::string(d.key));
    REQUIRE(it != values.end());
    CHECK(it->second == d.text);
  }
  CHECK(LoadFile(active, &warnings) == LayerSettings{});
  CHECK(warnings.empty());
}
