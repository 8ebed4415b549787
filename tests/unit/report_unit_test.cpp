// The reporter without a driver: message ids, filters (names, suffixes, ids, renumbered rules), the
// duplicate limit, severities and their counts, messenger delivery and skip, the JSON-lines report, paths.
#include <unistd.h>

#include <catch2/catch_test_macros.hpp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "temp_report.h"
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

// Message ids the Khronos validation layer itself printed ("| MessageID = 0x..."), so asval's ids match
// filters written for that layer. Each pair comes from outside asval:
constexpr uint32_t kId03710 = 0x63ff8904;  // Debian 12's VK_LAYER_KHRONOS_validation 1.3.239, run alone on
                                           // examples/minimal (misaligned scratch), its stderr
constexpr uint32_t kId10126 = 0xd46589c2;  // layer 1.3.296 output quoted in
                                           // github.com/DerRM/VulkanRaytracingProceduralGeometry/issues/3
constexpr const char* k03673 = "VUID-vkCmdBuildAccelerationStructuresKHR-geometry-03673";
constexpr uint32_t kId03673 = 0x8a7de95d;  // layer 1.3.216 output quoted in
                                           // github.com/Apress/Ray-Tracing-Gems-II/issues/5
constexpr const char* kDstParameter =
    "VUID-VkAccelerationStructureBuildGeometryInfoKHR-dstAccelerationStructure-parameter";
constexpr uint32_t kIdDstParameter = 0x45e8716f;  // layer 1.2.148 output quoted in
                                                  // github.com/nvpro-samples/vk_raytracing_tutorial_KHR/issues/9

TEST_CASE("message ids are the Khronos layer's: known pairs", "[report]") {
  CHECK(MessageIdHash(k03710) == kId03710);
  CHECK(MessageIdHash(k10126) == kId10126);
  CHECK(MessageIdHash(k03673) == kId03673);
  CHECK(MessageIdHash(kDstParameter) == kIdDstParameter);
}

TEST_CASE("filters: full name, suffix at a '-' boundary, id, renumbered rules", "[report]") {
  CHECK(MessageFilter({k03710}).Mutes(k03710, kId03710));
  CHECK(MessageFilter({"03710"}).Mutes(k03710, kId03710));
  CHECK_FALSE(MessageFilter({"3710"}).Mutes(k03710, kId03710));
  CHECK(MessageFilter({"0x63ff8904"}).Mutes(k03710, kId03710));
  CHECK(MessageFilter({"1677691140"}).Mutes(k03710, kId03710));  // 0x63ff8904 in decimal
  // The destination-size rule is reported as 10126; muting its old name 03675 mutes it.
  CHECK(MessageFilter({k03675}).Mutes(k10126, kId10126));
  CHECK(MessageFilter({"03675"}).Mutes(k10126, kId10126));
  CHECK_FALSE(MessageFilter({"03675"}).Mutes(k03710, kId03710));
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

TEST_CASE("info messages are counted as info, not as warnings", "[report]") {
  ReportSettings settings;
  settings.report_info = true;
  Reporter reporter(settings);
  const Location loc("vkCmdBuildAccelerationStructuresKHR");
  reporter.Report(Severity::kInfo, "ASVAL-Info-One", loc, {}, "informational");
  reporter.Report(Severity::kInfo, "ASVAL-Info-Two", loc, {}, "informational");
  reporter.Report(Severity::kWarning, "ASVAL-Warning-One", loc, {}, "a warning");
  CHECK(reporter.InfoCount() == 2);
  CHECK(reporter.WarningCount() == 1);
  CHECK(reporter.ErrorCount() == 0);
}

using asval_test_common::Printable;
using asval_test_common::TempReport;

// U+FFFD REPLACEMENT CHARACTER in UTF-8: what each invalid byte of a name becomes in the report.
constexpr const char* kReplacement = "\xEF\xBF\xBD";
// A device handle for the names (the reporter only compares it).
const VkDevice kDevice = reinterpret_cast<VkDevice>(uintptr_t{0x4000});

TEST_CASE("object names end with their objects, are kept per type, and only for the types messages name",
          "[report]") {
  TempReport file;
  ReportSettings settings;
  settings.report_file = file.path;
  Reporter reporter(settings);
  const VkDevice other = reinterpret_cast<VkDevice>(uintptr_t{0x8000});
  reporter.SetObjectName(kDevice, VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x10, "dead structure");
  reporter.SetObjectName(kDevice, VK_OBJECT_TYPE_COMMAND_BUFFER, 0x10, "same value, another type");
  reporter.SetObjectName(kDevice, VK_OBJECT_TYPE_QUEUE, 0x20, "queue of the first device");
  reporter.SetObjectName(other, VK_OBJECT_TYPE_QUEUE, 0x30, "queue of the other device");
  reporter.SetObjectName(kDevice, VK_OBJECT_TYPE_IMAGE, 0x40, "an image: never in a message, not kept");
  // The structure is destroyed; a new one gets its handle value.
  reporter.ForgetObjectName(ReportObject{VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x10});
  reporter.ForgetObjectNames(kDevice);  // the first device is destroyed: its queue's name goes, not the other's
  reporter.Report(Severity::kError, k03710, Location("vkCmdBuildAccelerationStructuresKHR"),
                  {ReportObject{VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x10},
                   ReportObject{VK_OBJECT_TYPE_QUEUE, 0x20}, ReportObject{VK_OBJECT_TYPE_QUEUE, 0x30},
                   ReportObject{VK_OBJECT_TYPE_IMAGE, 0x40}},
                  "m");
  const std::vector<std::string> lines = file.Lines();
  REQUIRE(lines.size() == 1);
  const nlohmann::json objects = nlohmann::json::parse(lines[0])["objects"];
  REQUIRE(objects.size() == 4);
  CHECK_FALSE(objects[0].contains("name"));
  CHECK_FALSE(objects[1].contains("name"));
  CHECK(objects[2]["name"] == "queue of the other device");
  CHECK_FALSE(objects[3].contains("name"));
  // The command buffer of the same handle value kept its own name until it was freed.
  TempReport second;
  ReportSettings settings2;
  settings2.report_file = second.path;
  Reporter reporter2(settings2);
  reporter2.SetObjectName(kDevice, VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x10, "structure");
  reporter2.SetObjectName(kDevice, VK_OBJECT_TYPE_COMMAND_BUFFER, 0x10, "command buffer");
  reporter2.ForgetObjectName(ReportObject{VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x10});
  reporter2.Report(Severity::kError, k03710, Location("vkCmdBuildAccelerationStructuresKHR"),
                   {ReportObject{VK_OBJECT_TYPE_COMMAND_BUFFER, 0x10},
                    ReportObject{VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x10}},
                   "m");
  const nlohmann::json objects2 = nlohmann::json::parse(second.Lines().at(0))["objects"];
  CHECK(objects2[0]["name"] == "command buffer");
  CHECK_FALSE(objects2[1].contains("name"));
}

TEST_CASE("report_file lines parse as JSON whatever the object names hold", "[report]") {
  TempReport file;
  {
    ReportSettings settings;
    settings.report_file = file.path;
    Reporter reporter(settings);
    const std::string tricky = "say \"hi\" \\ tab\t newline\n bell\x07 caf\xC3\xA9";  // valid UTF-8
    reporter.SetObjectName(kDevice, VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x1234, "\xff\xfe");  // not UTF-8 at all
    reporter.SetObjectName(kDevice, VK_OBJECT_TYPE_QUEUE, 0x5678, tricky.c_str());
    reporter.Report(Severity::kError, k03710, Location("vkCmdBuildAccelerationStructuresKHR").Field("pInfos", 0).Field("scratchData"),
                    {ReportObject{VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, 0x1234},
                     ReportObject{VK_OBJECT_TYPE_COMMAND_BUFFER, 0},
                     ReportObject{VK_OBJECT_TYPE_QUEUE, 0x5678}},
                    "a \"quoted\" message\n");
    reporter.LayerNotice(Severity::kWarning, "a notice with \xff in it");

    const std::vector<std::string> lines = file.Lines();
    REQUIRE(lines.size() == 2);
    for (const std::string& line : lines) {
      INFO(Printable(line));
      REQUIRE(nlohmann::json::accept(line));
    }
    const nlohmann::json finding = nlohmann::json::parse(lines[0]);
    CHECK(finding["severity"] == "error");
    CHECK(finding["vuid"] == k03710);
    CHECK(finding["message_id"] == "0x63ff8904");
    CHECK(finding["function"] == "vkCmdBuildAccelerationStructuresKHR");
    CHECK(finding["location"] == "pInfos[0].scratchData");
    CHECK(finding["message"] == "a \"quoted\" message\n");
    CHECK(finding["spec_text"].get<std::string>().find("minAccelerationStructureScratchOffsetAlignment") !=
          std::string::npos);
    const nlohmann::json& objects = finding["objects"];
    REQUIRE(objects.size() == 2);  // the null command buffer is left out
    CHECK(objects[0]["type"] == "VkAccelerationStructureKHR");
    CHECK(objects[0]["handle"] == "0x1234");
    CHECK(objects[0]["name"] == std::string(kReplacement) + kReplacement);
    CHECK(objects[1]["type"] == "VkQueue");
    CHECK(objects[1]["handle"] == "0x5678");
    CHECK(objects[1]["name"] == tricky);
    // Keys in the order the report has always had: readers that print lines raw see the same thing.
    CHECK(lines[0].rfind("{\"severity\":\"error\",\"vuid\":\"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710\","
                         "\"message_id\":\"0x63ff8904\",\"function\":", 0) == 0);

    const nlohmann::json notice = nlohmann::json::parse(lines[1]);
    CHECK(notice["severity"] == "warning");
    CHECK(notice["vuid"] == "ASVAL-layer-notice");
    CHECK(notice["message"] == std::string("a notice with ") + kReplacement + " in it");
  }
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
