// The reporter without a driver: filters (names, suffixes, ids, renumbered rules), the duplicate limit,
// severities, messenger delivery and skip, paths.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include <catch2/catch_test_macros.hpp>
#include <cstring>
#include <string>
#include <vector>

#include "location.h"
#include "message_id.h"
#include "reporter.h"

namespace asval {
namespace {

struct Sink {
  std::vector<std::string> ids;
  std::vector<std::string> texts;
  VkBool32 answer = VK_FALSE;
  static VKAPI_ATTR VkBool32 VKAPI_CALL Callback(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<Sink*>(user);
    self->ids.push_back(data->pMessageIdName);
    self->texts.push_back(data->pMessage);
    return self->answer;
  }
  VkDebugUtilsMessengerCreateInfoEXT Info(VkDebugUtilsMessageSeverityFlagsEXT severities =
                                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = severities;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    info.pfnUserCallback = &Sink::Callback;
    info.pUserData = this;
    return info;
  }
};

VkDebugUtilsMessengerEXT FakeMessenger(uintptr_t v) { return reinterpret_cast<VkDebugUtilsMessengerEXT>(v); }

constexpr const char* k03710 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710";
constexpr const char* k10126 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-10126";
constexpr const char* k03675 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03675";

TEST_CASE("message ids are the Khronos layer's XXH32 hashes", "[report]") {
  CHECK(MessageIdHash(k03710) == XXH32(k03710, std::strlen(k03710), 8));
  CHECK(MessageIdHash(k03710) != MessageIdHash(k10126));
}

TEST_CASE("filters: full name, suffix at a '-' boundary, id, renumbered rules", "[report]") {
  CHECK(MessageFilter({k03710}).Mutes(k03710, MessageIdHash(k03710)));
  CHECK(MessageFilter({"03710"}).Mutes(k03710, MessageIdHash(k03710)));
  CHECK_FALSE(MessageFilter({"3710"}).Mutes(k03710, MessageIdHash(k03710)));
  char hex[16];
  std::snprintf(hex, sizeof(hex), "0x%x", MessageIdHash(k03710));
  CHECK(MessageFilter({hex}).Mutes(k03710, MessageIdHash(k03710)));
  CHECK(MessageFilter({std::to_string(MessageIdHash(k03710))}).Mutes(k03710, MessageIdHash(k03710)));
  // The destination-size rule is reported as 10126; muting its old name 03675 mutes it.
  CHECK(MessageFilter({k03675}).Mutes(k10126, MessageIdHash(k10126)));
  CHECK(MessageFilter({"03675"}).Mutes(k10126, MessageIdHash(k10126)));
  CHECK_FALSE(MessageFilter({"03675"}).Mutes(k03710, MessageIdHash(k03710)));
  // Layer-specific ids are matched by name and suffix.
  CHECK(MessageFilter({"ASVAL-Settings-Invalid"}).Mutes("ASVAL-Settings-Invalid", MessageIdHash("ASVAL-Settings-Invalid")));
  CHECK(MessageFilter({"Invalid"}).Mutes("ASVAL-Settings-Invalid", MessageIdHash("ASVAL-Settings-Invalid")));
}

TEST_CASE("older spellings are reported under the newest VUID", "[report]") {
  Sink sink;
  Reporter reporter(ReportSettings{});
  reporter.AddMessenger(FakeMessenger(1), sink.Info());
  reporter.Report(Severity::kError, k03675, Location("vkCmdBuildAccelerationStructuresKHR"), {}, "too small");
  REQUIRE(sink.ids.size() == 1);
  CHECK(sink.ids[0] == k10126);
}

TEST_CASE("duplicate limit, severities, skip and removal of messengers", "[report]") {
  Sink sink;
  ReportSettings settings;
  settings.duplicate_message_limit = 3;
  settings.report_warnings = false;
  Reporter reporter(settings);
  reporter.AddMessenger(FakeMessenger(7), sink.Info());
  const Location loc("vkCmdBuildAccelerationStructuresKHR");
  for (int i = 0; i < 5; ++i) reporter.Report(Severity::kError, k03710, loc, {}, "x");
  CHECK(sink.ids.size() == 3);
  CHECK(sink.texts[2].find("this will be the last time reporting it") != std::string::npos);
  CHECK(reporter.ErrorCount() == 3);
  reporter.Report(Severity::kWarning, "ASVAL-Something", loc, {}, "muted by severity");
  CHECK(sink.ids.size() == 3);
  sink.answer = VK_TRUE;
  CHECK(reporter.Report(Severity::kError, k10126, loc, {}, "skip me"));
  reporter.RemoveMessenger(FakeMessenger(7));
  CHECK_FALSE(reporter.Report(Severity::kError, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03711", loc, {}, "to stderr"));
  CHECK(sink.ids.size() == 4);
}

TEST_CASE("create-time messengers are dropped after creation", "[report]") {
  Sink sink;
  Reporter reporter(ReportSettings{});
  reporter.AddMessenger(VK_NULL_HANDLE, sink.Info());
  reporter.RemoveCreateTimeMessengers();
  reporter.Report(Severity::kError, k03710, Location("vkCmdBuildAccelerationStructuresKHR"), {}, "x");
  CHECK(sink.ids.empty());
}

TEST_CASE("locations print Vulkan parameter paths", "[report]") {
  const Location root("vkCmdBuildAccelerationStructuresKHR");
  CHECK(root.Path().empty());
  const Location loc = root.Field("pInfos", 1).Field("pGeometries", 0).Field("geometry").Field("triangles").Field("vertexData");
  CHECK(loc.Path() == "pInfos[1].pGeometries[0].geometry.triangles.vertexData");
  CHECK(std::string(loc.Function()) == "vkCmdBuildAccelerationStructuresKHR");
}

}  // namespace
}  // namespace asval
