// Values written as text (environment, settings file): forms accepted, malformed values, unknown keys.
#include <catch2/catch_test_macros.hpp>

#include "settings_test_support.h"

using namespace asval;
using asval::test::FakeSources;
using asval::test::HasWarning;
using asval::test::WriteFile;
using Items = std::vector<std::string>;

namespace {

// Loads with `text` as the working directory's vk_layer_settings.txt.
LayerSettings LoadFile(const std::string& text, std::vector<std::string>* warnings) {
  FakeSources fake;
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", text);
  return LoadLayerSettings(fake.Get(), nullptr, warnings);
}

// Loads with one environment variable set.
LayerSettings LoadEnv(const std::string& name, const std::string& value, std::vector<std::string>* warnings) {
  FakeSources fake;
  fake.env[name] = value;
  return LoadLayerSettings(fake.Get(), nullptr, warnings);
}

}  // namespace

TEST_CASE("report_flags takes a list of flag names", "[settings][values]") {
  std::vector<std::string> warnings;
  CHECK(LoadFile("asval_as_validation.report_flags = info\n", &warnings).report_flags == kSeverityInfo);
  CHECK(LoadFile("asval_as_validation.report_flags = error, warn ,info\n", &warnings).report_flags ==
        (kSeverityError | kSeverityWarn | kSeverityInfo));
  CHECK(LoadEnv("VK_ASVAL_AS_VALIDATION_REPORT_FLAGS", "warn:info", &warnings).report_flags ==
        (kSeverityWarn | kSeverityInfo));
  CHECK(LoadEnv("VK_REPORT_FLAGS", ",", &warnings).report_flags == 0u);  // a list of no flags
  CHECK(warnings.empty());
  const LayerSettings s = LoadFile("asval_as_validation.report_flags = error\n", &warnings);
  CHECK(s.Reports(kSeverityError));
  CHECK_FALSE(s.Reports(kSeverityWarn));
}

TEST_CASE("capture takes one of its value names", "[settings][values][enum]") {
  std::vector<std::string> warnings;
  CHECK(LoadFile("asval_as_validation.capture = off\n", &warnings).capture == kCaptureOff);
  CHECK(LoadFile("asval_as_validation.capture = all\n", &warnings).capture == kCaptureAll);
  CHECK(LoadEnv("VK_ASVAL_AS_VALIDATION_CAPTURE", "all", &warnings).capture == kCaptureAll);
  CHECK(LoadEnv("VK_CAPTURE", " off ", &warnings).capture == kCaptureOff);  // trimmed, like a flag name
  CHECK(warnings.empty());

  // The environment beats the file, as for every other type.
  FakeSources fake;
  fake.env["VK_AS_VALIDATION_CAPTURE"] = "off";
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", "asval_as_validation.capture = all\n");
  CHECK(LoadLayerSettings(fake.Get(), nullptr, &warnings).capture == kCaptureOff);
  CHECK(warnings.empty());
}

TEST_CASE("message_id_filter splits on ',' if present, else on ':'", "[settings][values]") {
  std::vector<std::string> warnings;
  CHECK(
      LoadFile("asval_as_validation.message_id_filter = VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710, 03667\n",
               &warnings)
          .message_id_filter == Items{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710", "03667"});
  CHECK(LoadEnv("VK_MESSAGE_ID_FILTER", "03710:0xDEADBEEF:12345", &warnings).message_id_filter ==
        Items{"03710", "0xDEADBEEF", "12345"});
  CHECK(LoadEnv("VK_MESSAGE_ID_FILTER", "a:b,c", &warnings).message_id_filter == Items{"a:b", "c"});
  CHECK(warnings.empty());
}

TEST_CASE("string settings are taken verbatim, never split", "[settings][values]") {
  std::vector<std::string> warnings;
  CHECK(LoadEnv("VK_ASVAL_AS_VALIDATION_REPORT_FILE", "/tmp/a:b,c.jsonl", &warnings).report_file == "/tmp/a:b,c.jsonl");
  CHECK(LoadFile("asval_as_validation.report_file =   /tmp/with space.jsonl  \n", &warnings).report_file ==
        "/tmp/with space.jsonl");
  CHECK(warnings.empty());
}

TEST_CASE("booleans: true/false, on/off, integers", "[settings][values]") {
  std::vector<std::string> warnings;
  for (const char* yes : {"true", "TRUE", "on", "On", "1", "0x1", "7"}) {
    CAPTURE(yes);
    CHECK(LoadEnv("VK_LOG_TO_STDERR", yes, &warnings).log_to_stderr);
  }
  for (const char* no : {"false", "False", "off", "OFF", "0", "0x0"}) {
    CAPTURE(no);
    FakeSources fake;
    fake.env["VK_LOG_TO_STDERR"] = no;
    WriteFile(fake.Cwd() / "vk_layer_settings.txt", "asval_as_validation.log_to_stderr = true\n");
    CHECK_FALSE(LoadLayerSettings(fake.Get(), nullptr, &warnings).log_to_stderr);  // env false beats file true
  }
  CHECK(warnings.empty());
}

TEST_CASE("integers: decimal and 0x hexadecimal, within the range", "[settings][values]") {
  std::vector<std::string> warnings;
  CHECK(LoadFile("asval_as_validation.duplicate_message_limit = 0\n", &warnings).duplicate_message_limit == 0);
  CHECK(LoadFile("asval_as_validation.duplicate_message_limit = 0x10\n", &warnings).duplicate_message_limit == 16);
  CHECK(LoadEnv("VK_DUPLICATE_MESSAGE_LIMIT", "4294967295", &warnings).duplicate_message_limit == 4294967295u);
  CHECK(LoadFile("asval_as_validation.capture_budget_mb = 1\n", &warnings).capture_budget_mb == 1);
  CHECK(LoadEnv("VK_CAPTURE_BUDGET_MB", "65536", &warnings).capture_budget_mb == 65536);
  CHECK(warnings.empty());
}

TEST_CASE("malformed values give a warning and keep the default", "[settings][values][malformed]") {
  struct Case {
    const char* line;
    const char* expect_in_warning;
  };
  for (const Case& c : {
           Case{"asval_as_validation.duplicate_message_limit = ten", "'ten' is not an integer"},
           Case{"asval_as_validation.duplicate_message_limit = 12abc", "'12abc' is not an integer"},
           Case{"asval_as_validation.duplicate_message_limit = -1", "outside the range 0..4294967295"},
           Case{"asval_as_validation.duplicate_message_limit = 4294967296", "outside the range"},
           Case{"asval_as_validation.log_to_stderr = yes", "'yes' is not a boolean"},
           Case{"asval_as_validation.report_flags = error,bogus",
                "'bogus' is not one of its flags (error, warn, info)"},
           Case{"asval_as_validation.report_flags = Error", "'Error' is not one of its flags"},
           Case{"asval_as_validation.capture = everything",
                "'everything' is not one of its values (off, updates, all)"},
           Case{"asval_as_validation.capture = All", "'All' is not one of its values"},  // case-sensitive
           Case{"asval_as_validation.capture = off,all", "'off,all' is not one of its values"},  // exactly one
           Case{"asval_as_validation.capture_budget_mb = 0", "outside the range 1..65536"},
           Case{"asval_as_validation.capture_budget_mb = 65537", "outside the range 1..65536"},
       }) {
    CAPTURE(c.line);
    std::vector<std::string> warnings;
    CHECK(LoadFile(std::string(c.line) + "\n", &warnings) == LayerSettings{});
    REQUIRE(warnings.size() == 1);
    CHECK(HasWarning(warnings, "settings file", c.expect_in_warning, "keeps its default"));
  }
}

TEST_CASE("a malformed environment value does not fall back to the file", "[settings][values][malformed]") {
  FakeSources fake;
  fake.env["VK_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT"] = "lots";
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", "asval_as_validation.duplicate_message_limit = 3\n");
  std::vector<std::string> warnings;
  CHECK(LoadLayerSettings(fake.Get(), nullptr, &warnings).duplicate_message_limit == 10);
  REQUIRE(warnings.size() == 1);
  CHECK(HasWarning(warnings, "environment variable VK_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT", "'lots'",
                   "duplicate_message_limit keeps its default (10)"));
}

TEST_CASE("an unknown capture value from the environment keeps the default", "[settings][values][malformed][enum]") {
  FakeSources fake;
  fake.env["VK_CAPTURE"] = "updates-only";
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", "asval_as_validation.capture = all\n");
  std::vector<std::string> warnings;
  CHECK(LoadLayerSettings(fake.Get(), nullptr, &warnings).capture == kCaptureUpdates);
  REQUIRE(warnings.size() == 1);
  CHECK(HasWarning(warnings, "environment variable VK_CAPTURE", "'updates-only' is not one of its values",
                   "capture keeps its default (updates)"));
}

TEST_CASE("unknown keys of this layer in the file give a warning; other layers' keys do not",
          "[settings][values][unknown]") {
  std::vector<std::string> warnings;
  const LayerSettings s = LoadFile(
      "asval_as_validation.no_such_setting = 1\n"
      "asval_as_validation.Log_To_Stderr = true\n"  // setting names are case-sensitive
      "khronos_validation.report_flags = error\n"
      "ASVAL_AS_VALIDATION.log_to_stderr = true\n"  // not this layer's prefix (it is lower case)
      "asval_as_validation.duplicate_message_limit = 4\n",
      &warnings);
  CHECK(s.duplicate_message_limit == 4);
  CHECK_FALSE(s.log_to_stderr);
  CHECK(warnings.size() == 2);
  CHECK(HasWarning(warnings, "unknown setting 'asval_as_validation.no_such_setting'"));
  CHECK(HasWarning(warnings, "unknown setting 'asval_as_validation.Log_To_Stderr'"));
}
