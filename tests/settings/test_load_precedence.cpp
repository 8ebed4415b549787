// Which source wins: environment > settings file > VkLayerSettingsCreateInfoEXT, per setting (guide 3.1 item 1),
// the three environment names in order (item 4), and which settings file is read (item 2).
#include <catch2/catch_test_macros.hpp>

#include <cstdlib>

#include "settings_test_support.h"

using namespace asval;
using asval::test::CreateInfo;
using asval::test::Entry;
using asval::test::FakeSources;
using asval::test::HasWarning;
using asval::test::WriteFile;

namespace {

LayerSettings Load(const FakeSources& fake, const void* pNext = nullptr, std::vector<std::string>* warnings = nullptr) {
  return LoadLayerSettings(fake.Get(), pNext, warnings);
}

}  // namespace

TEST_CASE("environment beats file beats API, setting by setting", "[settings][precedence]") {
  FakeSources fake;
  const uint32_t api_limit = 30;
  const VkBool32 api_true = VK_TRUE;
  const char* api_file = "api.jsonl";
  const std::vector<VkLayerSettingEXT> entries = {
      Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &api_limit),
      Entry("log_to_stderr", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &api_true),
      Entry("report_file", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &api_file),
  };
  const VkLayerSettingsCreateInfoEXT info = CreateInfo(entries);

  // API alone.
  LayerSettings s = Load(fake, &info);
  CHECK(s.duplicate_message_limit == 30);
  CHECK(s.log_to_stderr);
  CHECK(s.report_file == "api.jsonl");

  // The file overrides the API for the settings it names.
  WriteFile(fake.Cwd() / "vk_layer_settings.txt",
            "asval_as_validation.duplicate_message_limit = 20\n"
            "asval_as_validation.report_file = file.jsonl\n");
  s = Load(fake, &info);
  CHECK(s.duplicate_message_limit == 20);
  CHECK(s.report_file == "file.jsonl");
  CHECK(s.log_to_stderr);  // still from the API

  // The environment overrides both.
  fake.env["VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT"] = "10";
  s = Load(fake, &info);
  CHECK(s.duplicate_message_limit == 10);
  CHECK(s.report_file == "file.jsonl");
  CHECK(s.log_to_stderr);
}

TEST_CASE("an empty environment or file value counts as unset", "[settings][precedence]") {
  FakeSources fake;
  const uint32_t api_limit = 30;
  const std::vector<VkLayerSettingEXT> entries = {
      Entry("duplicate_message_limit", VK_LAYER_SETTING_TYPE_UINT32_EXT, 1, &api_limit)};
  const VkLayerSettingsCreateInfoEXT info = CreateInfo(entries);
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", "asval_as_validation.duplicate_message_limit =\n");
  fake.env["VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT"] = "";
  CHECK(Load(fake, &info).duplicate_message_limit == 30);
}

TEST_CASE("environment names are tried in order; the first non-empty one wins", "[settings][precedence][env]") {
  FakeSources fake;
  SECTION("each form works alone") {
    for (const char* name : {"VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT",
                             "VK_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT", "VK_DUPLICATE_MESSAGE_LIMIT"}) {
      CAPTURE(name);
      fake.env[name] = "7";
      CHECK(Load(fake).duplicate_message_limit == 7);
      fake.env.erase(name);
    }
  }
  SECTION("VK_ASVAL_AS_VALIDATION_ beats VK_AS_VALIDATION_ beats VK_") {
    fake.env["VK_DUPLICATE_MESSAGE_LIMIT"] = "3";
    CHECK(Load(fake).duplicate_message_limit == 3);
    fake.env["VK_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT"] = "2";
    CHECK(Load(fake).duplicate_message_limit == 2);
    fake.env["VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT"] = "1";
    CHECK(Load(fake).duplicate_message_limit == 1);
    fake.env["VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT"] = "";  // empty: fall to the next form
    CHECK(Load(fake).duplicate_message_limit == 2);
  }
  SECTION("names are upper case only") {
    fake.env["VK_ASVAL_AS_VALIDATION_duplicate_message_limit"] = "7";
    fake.env["vk_asval_as_validation_duplicate_message_limit"] = "7";
    CHECK(Load(fake).duplicate_message_limit == 10);
  }
}

TEST_CASE("only the first settings file found is read", "[settings][precedence][file]") {
  FakeSources fake;
  WriteFile(fake.VkconfigFile(), "asval_as_validation.duplicate_message_limit = 1\n");
  const auto env_dir = fake.Root() / "env_dir";
  WriteFile(env_dir / "vk_layer_settings.txt",
            "asval_as_validation.duplicate_message_limit = 2\nasval_as_validation.log_to_stderr = true\n");
  WriteFile(fake.Cwd() / "vk_layer_settings.txt",
            "asval_as_validation.duplicate_message_limit = 3\nasval_as_validation.report_file = cwd.jsonl\n");
  fake.env["VK_LAYER_SETTINGS_PATH"] = env_dir.string();

  LayerSettings s = Load(fake);
  CHECK(s.duplicate_message_limit == 1);
  CHECK_FALSE(s.log_to_stderr);  // the VK_LAYER_SETTINGS_PATH file is not merged in
  CHECK(s.report_file.empty());  // nor the working directory's

  std::filesystem::remove(fake.VkconfigFile());
  s = Load(fake);
  CHECK(s.duplicate_message_limit == 2);
  CHECK(s.log_to_stderr);
  CHECK(s.report_file.empty());

  fake.env["VK_LAYER_SETTINGS_PATH"] = (env_dir / "vk_layer_settings.txt").string();  // a file path works too
  CHECK(Load(fake).duplicate_message_limit == 2);

  fake.env.erase("VK_LAYER_SETTINGS_PATH");
  s = Load(fake);
  CHECK(s.duplicate_message_limit == 3);
  CHECK(s.report_file == "cwd.jsonl");
}

TEST_CASE("a VK_LAYER_SETTINGS_PATH directory without the file ends the search, with a warning",
          "[settings][precedence][file]") {
  FakeSources fake;
  const auto empty_dir = fake.Root() / "empty_dir";
  std::filesystem::create_directories(empty_dir);
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", "asval_as_validation.duplicate_message_limit = 3\n");
  fake.env["VK_LAYER_SETTINGS_PATH"] = empty_dir.string();
  std::vector<std::string> warnings;
  CHECK(Load(fake, nullptr, &warnings).duplicate_message_limit == 10);  // VUL does not fall back to the cwd
  CHECK(HasWarning(warnings, "VK_LAYER_SETTINGS_PATH", "empty_dir/vk_layer_settings.txt"));
}

TEST_CASE("no sources at all gives the defaults and no warnings", "[settings][precedence]") {
  FakeSources fake;
  std::vector<std::string> warnings;
  CHECK(Load(fake, nullptr, &warnings) == LayerSettings{});
  CHECK(warnings.empty());
}

TEST_CASE("the process-environment overload reads the real environment", "[settings][precedence][env]") {
  asval::test::TempDir dir;
  const char* old_data_home = std::getenv("XDG_DATA_HOME");
  const std::string saved_data_home = old_data_home != nullptr ? old_data_home : "";
  // XDG_DATA_HOME keeps this machine's vkconfig file out of the way.
  REQUIRE(setenv("XDG_DATA_HOME", dir.str().c_str(), 1) == 0);
  WriteFile(dir.path() / "settings.txt", "asval_as_validation.log_to_stderr = on\n");
  REQUIRE(setenv("VK_LAYER_SETTINGS_PATH", (dir.path() / "settings.txt").c_str(), 1) == 0);
  REQUIRE(setenv("VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT", "0x20", 1) == 0);
  std::vector<std::string> warnings;
  const LayerSettings s = LoadLayerSettings(nullptr, &warnings);
  unsetenv("VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT");
  unsetenv("VK_LAYER_SETTINGS_PATH");
  if (old_data_home != nullptr) {
    setenv("XDG_DATA_HOME", saved_data_home.c_str(), 1);
  } else {
    unsetenv("XDG_DATA_HOME");
  }
  CHECK(s.duplicate_message_limit == 32);
  CHECK(s.log_to_stderr);
  CHECK(warnings.empty());
}
