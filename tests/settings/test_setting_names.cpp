// Environment and file names of settings (guide section 3.1 items 3 and 4).
#include <catch2/catch_test_macros.hpp>

#include "layer_settings.h"
#include "setting_names.h"

using namespace asval::settings_detail;

TEST_CASE("the layer name is the manifest's", "[settings][names]") {
  CHECK(std::string(asval::kLayerName) == "VK_LAYER_ASVAL_as_validation");
}

TEST_CASE("file keys are the lower-cased layer name without VK_LAYER_, a dot, and the setting", "[settings][names]") {
  CHECK(FileKeyPrefix(asval::kLayerName) == "asval_as_validation.");
  CHECK(FileSettingKey(asval::kLayerName, "duplicate_message_limit") == "asval_as_validation.duplicate_message_limit");
  // Same rule as VUL on another layer: only the prefix is lower-cased.
  CHECK(FileSettingKey("VK_LAYER_KHRONOS_validation", "Mixed_Case") == "khronos_validation.Mixed_Case");
}

TEST_CASE("environment names come in TRIM_NONE, TRIM_VENDOR, TRIM_NAMESPACE order", "[settings][names]") {
  const auto names = EnvSettingNames(asval::kLayerName, "duplicate_message_limit");
  CHECK(names[0] == "VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT");
  CHECK(names[1] == "VK_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT");
  CHECK(names[2] == "VK_DUPLICATE_MESSAGE_LIMIT");
  // VUL's documented example.
  const auto vvl = EnvSettingNames("VK_LAYER_KHRONOS_validation", "debug_action");
  CHECK(vvl[0] == "VK_KHRONOS_VALIDATION_DEBUG_ACTION");
  CHECK(vvl[1] == "VK_VALIDATION_DEBUG_ACTION");
  CHECK(vvl[2] == "VK_DEBUG_ACTION");
}
