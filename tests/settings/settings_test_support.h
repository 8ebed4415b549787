// Test helpers: a private temporary directory, file writing, and a fake environment for SettingsSources.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "layer_settings.h"
#include "layer_settings_ext.h"

namespace asval::test {

// A fresh directory under $TMPDIR (or /tmp), removed with everything in it on destruction.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "asval_settings_XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

inline void WriteFile(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// SettingsSources over an in-memory environment. The working directory and XDG_DATA_HOME point into a
// temporary directory so that no settings file of the machine running the tests can leak in.
class FakeSources {
 public:
  FakeSources() : cwd_dir_("cwd"), data_home_("data_home") {
    std::filesystem::create_directories(root_.path() / "cwd");
    std::filesystem::create_directories(root_.path() / "data_home");
    env["XDG_DATA_HOME"] = (root_.path() / data_home_).string();
    env["HOME"] = (root_.path() / "no_home").string();
  }

  std::map<std::string, std::string> env;

  std::filesystem::path Root() const { return root_.path(); }
  std::filesystem::path Cwd() const { return root_.path() / cwd_dir_; }
  std::filesystem::path VkconfigFile() const {
    return root_.path() / data_home_ / "vulkan/settings.d/vk_layer_settings.txt";
  }

  SettingsSources Get() const {
    SettingsSources sources;
    sources.getenv = [this](const char* name) {
      const auto it = env.find(name);
      return it == env.end() ? std::string() : it->second;
    };
    sources.cwd = Cwd().string();
    return sources;
  }

 private:
  TempDir root_;
  std::string cwd_dir_;
  std::string data_home_;
};

// A VkLayerSettingsCreateInfoEXT over `entries`; the vector must outlive the returned chain and stay unchanged.
inline VkLayerSettingsCreateInfoEXT CreateInfo(const std::vector<VkLayerSettingEXT>& entries,
                                               const void* next = nullptr) {
  return VkLayerSettingsCreateInfoEXT{VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT, next,
                                      static_cast<uint32_t>(entries.size()), entries.data()};
}

// One entry for this layer.
inline VkLayerSettingEXT Entry(const char* setting, VkLayerSettingTypeEXT type, uint32_t count, const void* values) {
  return VkLayerSettingEXT{kLayerName, setting, type, count, values};
}

// True when some warning contains every one of the given fragments.
template <typename... Fragments>
bool HasWarning(const std::vector<std::string>& warnings, const Fragments&... fragments) {
  for (const std::string& w : warnings) {
    if (((w.find(fragments) != std::string::npos) && ...)) return true;
  }
  return false;
}

}  // namespace asval::test
