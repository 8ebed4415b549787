// The VUID table: lookup, spec text, and renumbered rules.
#include <catch2/catch_test_macros.hpp>

#include <string>
#include <string_view>

#include "vuid_table.h"

namespace {

constexpr std::string_view kScratchAlignment = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710";
constexpr std::string_view kDstSizeOld = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03675";
constexpr std::string_view kDstSizeNew = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-10126";

TEST_CASE("03710 is present with its spec text, in plain words") {
  const asval::VuidInfo* info = asval::FindVuid(kScratchAlignment);
  REQUIRE(info != nullptr);
  const std::string text = info->spec_text;
  CHECK(text.find("minAccelerationStructureScratchOffsetAlignment") != std::string::npos);
  CHECK(text.rfind("For each element of pInfos, its scratchData.deviceAddress member must be a multiple of", 0) == 0);
  CHECK(info->newest == kScratchAlignment);
}

TEST_CASE("no spec text keeps markup, and every entry has text") {
  for (std::size_t i = 0; i < asval::VuidCount(); ++i) {
    const asval::VuidInfo* info = asval::VuidAt(i);
    INFO(info->vuid);
    const std::string_view text = info->spec_text;
    CHECK(!text.empty());
    CHECK(text.find('<') == std::string_view::npos);  // no HTML tags (no text compares with <)
    CHECK(text.find('`') == std::string_view::npos);
    CHECK(text.find("**") == std::string_view::npos);
    CHECK(text.find("pname:") == std::string_view::npos);
    CHECK(text.find("](") == std::string_view::npos);
    CHECK(text.find("&#") == std::string_view::npos);
    CHECK(text.find("  ") == std::string_view::npos);
  }
}

TEST_CASE("the table is sorted and every entry is found by its own name") {
  REQUIRE(asval::VuidCount() > 700);
  for (std::size_t i = 0; i < asval::VuidCount(); ++i) {
    const asval::VuidInfo* info = asval::VuidAt(i);
    if (i > 0) CHECK(std::string_view(asval::VuidAt(i - 1)->vuid) < std::string_view(info->vuid));
    CHECK(asval::FindVuid(info->vuid) == info);
    CHECK(asval::FindVuid(info->newest) != nullptr);  // the newest name is itself an entry
  }
  CHECK(asval::VuidAt(asval::VuidCount()) == nullptr);
}

TEST_CASE("unknown VUIDs are not found and stay as they are") {
  CHECK(asval::FindVuid("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-99999") == nullptr);
  CHECK(asval::FindVuid("") == nullptr);
  CHECK(asval::FindVuid("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-0371") == nullptr);  // a prefix
  CHECK(asval::NewestVuid("VUID-unknown") == "VUID-unknown");
}

TEST_CASE("renumbered rules resolve to their newest name") {
  CHECK(asval::NewestVuid(kDstSizeOld) == kDstSizeNew);
  CHECK(asval::NewestVuid(kDstSizeNew) == kDstSizeNew);
  CHECK(asval::NewestVuid("VUID-vkBuildAccelerationStructuresKHR-pInfos-03675") ==
        "VUID-vkBuildAccelerationStructuresKHR-pInfos-10126");
  CHECK(asval::NewestVuid("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03671") ==
        "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12258");
  CHECK(asval::NewestVuid("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03672") ==
        "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12259");
  CHECK(asval::NewestVuid("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-06707") ==
        "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12281");
  // The older name keeps its own (registry) text, which still explains the rule.
  const asval::VuidInfo* old_info = asval::FindVuid(kDstSizeOld);
  REQUIRE(old_info != nullptr);
  CHECK(std::string(old_info->spec_text).find("VkAccelerationStructureCreateInfoKHR::size") != std::string::npos);
  CHECK(std::string(asval::FindVuid(kDstSizeNew)->spec_text).find("COMPACTED_SIZE") != std::string::npos);
}

TEST_CASE("a filter naming an older VUID matches the newest one") {
  CHECK(asval::VuidMatches(kDstSizeOld, kDstSizeNew));
  CHECK(asval::VuidMatches(kDstSizeNew, kDstSizeNew));
  CHECK_FALSE(asval::VuidMatches(kDstSizeNew, kDstSizeOld));  // only older -> newer
  CHECK_FALSE(asval::VuidMatches(kScratchAlignment, kDstSizeNew));
  // 03674 (scratch buffer usage) was split by build mode into 12260 (update) and 12261 (build).
  constexpr std::string_view kUsageOld = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03674";
  CHECK(asval::VuidMatches(kUsageOld, "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12260"));
  CHECK(asval::VuidMatches(kUsageOld, "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12261"));
  CHECK(asval::NewestVuid(kUsageOld) == "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12260");
}

}  // namespace
