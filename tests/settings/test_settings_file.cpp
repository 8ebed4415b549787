// vk_layer_settings.txt: syntax (guide 3.1 item 3) and which file is read (item 2, VUL's code order).
#include <catch2/catch_test_macros.hpp>

#include "settings_file.h"
#include "settings_test_support.h"

using namespace asval::settings_detail;
using asval::test::FakeSources;
using asval::test::TempDir;
using asval::test::WriteFile;
using Origin = SettingsFileLocation::Origin;

TEST_CASE("settings text: comments, whitespace, '=' and duplicates", "[settings][file]") {
  const SettingsFileValues values = ParseSettingsText(
      "# a comment line\n"
      "   a.key   =   value with spaces   \r\n"
      "a.hash = before # after\n"
      "#a.commented = 1\n"
      "a.eq = x=y\n"
      "no equals sign here\n"
      "a.empty =\n"
      "a.dup = first\n"
      "\t a.dup\t=\tsecond\n"
      "a.last = no newline at end");
  CHECK(values.at("a.key") == "value with spaces");
  CHECK(values.at("a.hash") == "before");  // '#' cuts even inside a value
  CHECK(values.count("a.commented") == 0);
  CHECK(values.at("a.eq") == "x=y");  // split at the first '='
  CHECK(values.at("a.empty").empty());
  CHECK(values.at("a.dup") == "second");  // a later duplicate wins
  CHECK(values.at("a.last") == "no newline at end");
  CHECK(values.size() == 6);
}

TEST_CASE("ReadSettingsFile reports a missing file", "[settings][file]") {
  TempDir dir;
  SettingsFileValues values{{"keep", "me"}};
  CHECK_FALSE(ReadSettingsFile((dir.path() / "missing.txt").string(), &values));
  CHECK(values.at("keep") == "me");
  WriteFile(dir.path() / "present.txt", "k = v\n");
  REQUIRE(ReadSettingsFile((dir.path() / "present.txt").string(), &values));
  CHECK(values.size() == 1);
  CHECK(values.at("k") == "v");
}

TEST_CASE("settings file search order: vkconfig, then VK_LAYER_SETTINGS_PATH, then cwd", "[settings][file]") {
  FakeSources fake;
  const auto env_file = fake.Root() / "elsewhere/custom.txt";
  WriteFile(env_file, "");
  WriteFile(fake.Cwd() / "vk_layer_settings.txt", "");
  fake.env["VK_LAYER_SETTINGS_PATH"] = env_file.string();

  SECTION("the vkconfig file wins over both others") {
    WriteFile(fake.VkconfigFile(), "");
    const SettingsFileLocation found = FindSettingsFile(fake.Get());
    CHECK(found.origin == Origin::kVkconfig);
    CHECK(found.path == fake.VkconfigFile().string());
  }
  SECTION("without it, VK_LAYER_SETTINGS_PATH naming a file is used as is") {
    const SettingsFileLocation found = FindSettingsFile(fake.Get());
    CHECK(found.origin == Origin::kLayerSettingsPath);
    CHECK(found.path == env_file.string());
  }
  SECTION("a VK_LAYER_SETTINGS_PATH directory gets vk_layer_settings.txt appended") {
    fake.env["VK_LAYER_SETTINGS_PATH"] = (fake.Root() / "elsewhere").string();
    const SettingsFileLocation found = FindSettingsFile(fake.Get());
    CHECK(found.origin == Origin::kLayerSettingsPath);
    CHECK(found.path == (fake.Root() / "elsewhere").string() + "/vk_layer_settings.txt");
  }
  SECTION("a VK_LAYER_SETTINGS_PATH that does not exist is skipped") {
    fake.env["VK_LAYER_SETTINGS_PATH"] = (fake.Root() / "nowhere").string();
    const SettingsFileLocation found = FindSettingsFile(fake.Get());
    CHECK(found.origin == Origin::kWorkingDirectory);
    CHECK(found.path == fake.Cwd().string() + "/vk_layer_settings.txt");
  }
  SECTION("a vkconfig path that is a directory, not a file, is skipped") {
    std::filesystem::create_directories(fake.VkconfigFile());
    CHECK(FindSettingsFile(fake.Get()).origin == Origin::kLayerSettingsPath);
  }
}

TEST_CASE("the vkconfig file is under $HOME/.local/share only when XDG_DATA_HOME is unset", "[settings][file]") {
  FakeSources fake;
  const auto home = fake.Root() / "home";
  const auto home_file = home / ".local/share/vulkan/settings.d/vk_layer_settings.txt";
  WriteFile(home_file, "");
  fake.env["HOME"] = home.string();

  SECTION("XDG_DATA_HOME set (to a directory without the file): HOME is not consulted") {
    CHECK(FindSettingsFile(fake.Get()).origin == Origin::kWorkingDirectory);
  }
  SECTION("XDG_DATA_HOME unset") {
    fake.env.erase("XDG_DATA_HOME");
    const SettingsFileLocation found = FindSettingsFile(fake.Get());
    CHECK(found.origin == Origin::kVkconfig);
    CHECK(found.path == home_file.string());
  }
  SECTION("XDG_DATA_HOME empty counts as unset") {
    fake.env["XDG_DATA_HOME"] = "";
    CHECK(FindSettingsFile(fake.Get()).path == home_file.string());
  }
}

TEST_CASE("without a working directory the file name is relative", "[settings][file]") {
  FakeSources fake;
  asval::SettingsSources sources = fake.Get();
  sources.cwd.clear();
  CHECK(FindSettingsFile(sources).path == "vk_layer_settings.txt");
  sources.getenv = nullptr;  // no environment at all must not crash either
  CHECK(FindSettingsFile(sources).path == "vk_layer_settings.txt");
}
