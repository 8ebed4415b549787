// Reporting: the debug-utils callback data, object names, duplicate limit, mute list, JSON report, and
// settings given through VkLayerSettingsCreateInfoEXT (declared here as the 1.3.239 headers lack it).
#include <catch2/catch_test_macros.hpp>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <unistd.h>
#include <vector>

#include "temp_report.h"
#include "fixture.h"

namespace asval_test {
namespace {

constexpr const char* kVuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710";
// Its message id as the Khronos validation layer prints it (see tests/unit/report_unit_test.cpp for where
// this pair comes from).
constexpr uint32_t kVuidId = 0x63ff8904;

void RecordMisalignedBuilds(vkkit::Device& device, vkkit::TriangleBuild& build, int times) {
  build.UseScratchOffset(device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2);
  device.OneShot([&](VkCommandBuffer cb) {
    for (int i = 0; i < times; ++i) build.Record(device, cb);
  });
}

TEST_CASE("a finding carries the VUID, its hash, the path, the spec text and named objects", "[integration][report]") {
  Fixture f;
  vkkit::Device& device = f.device();
  vkkit::TriangleBuild build(device);
  device.SetName(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, reinterpret_cast<uint64_t>(build.blas.handle), "my BLAS");
  f.monitor().Expect(kVuid);
  RecordMisalignedBuilds(device, build, 1);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  const Message& m = messages[0];
  CHECK(m.severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT);
  CHECK(m.id_name == kVuid);
  CHECK(static_cast<uint32_t>(m.id_number) == kVuidId);
  CHECK(m.text.rfind("Validation Error: [ VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710 ]", 0) == 0);
  CHECK(m.text.find("vkCmdBuildAccelerationStructuresKHR(): pInfos[0].scratchData.deviceAddress") != std::string::npos);
  CHECK(m.text.find("The Vulkan spec states: ") != std::string::npos);
  CHECK(m.text.find("minAccelerationStructureScratchOffsetAlignment") != std::string::npos);
  CHECK(m.text.find("my BLAS") != std::string::npos);
  REQUIRE(m.objects.size() == 2);
  CHECK(m.objects[0].objectType == VK_OBJECT_TYPE_COMMAND_BUFFER);
  CHECK(m.objects[1].objectType == VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR);
  CHECK(m.objects[1].objectHandle == reinterpret_cast<uint64_t>(build.blas.handle));
  CHECK(m.names[1] == "my BLAS");
  build.Release(device);
}

TEST_CASE("a name ends with its object: a structure given a destroyed one's handle value is not shown under its "
          "name",
          "[integration][report]") {
  Fixture f;
  vkkit::Device& device = f.device();
  vkkit::TriangleBuild build(device);
  const VkAccelerationStructureKHR named = build.blas.handle;
  device.SetName(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, reinterpret_cast<uint64_t>(named), "dead BLAS");
  device.DestroyAccelerationStructureKHR(device.handle(), named, nullptr);
  // New structures on the same storage until the driver hands the dead one's handle value out again (lavapipe
  // reuses the freed object's memory at once).
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = build.blas.storage.buffer;
  info.size = build.blas.storage.size;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  std::vector<VkAccelerationStructureKHR> others;
  build.blas.handle = VK_NULL_HANDLE;
  for (int i = 0; i < 16 && build.blas.handle == VK_NULL_HANDLE; ++i) {
    VkAccelerationStructureKHR created = VK_NULL_HANDLE;
    vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &info, nullptr, &created),
                 "vkCreateAccelerationStructureKHR");
    (created == named ? build.blas.handle : others.emplace_back()) = created;
  }
  for (VkAccelerationStructureKHR other : others) device.DestroyAccelerationStructureKHR(device.handle(), other, nullptr);
  if (build.blas.handle == VK_NULL_HANDLE) {
    build.Release(device);
    SKIP("the driver did not hand the destroyed structure's handle value out again");
  }
  f.monitor().Expect(kVuid);
  RecordMisalignedBuilds(device, build, 1);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  REQUIRE(messages[0].objects.size() == 2);
  CHECK(messages[0].objects[1].objectHandle == reinterpret_cast<uint64_t>(named));
  CHECK(messages[0].names[1] == "");
  CHECK(messages[0].text.find("dead BLAS") == std::string::npos);
  build.Release(device);
}

TEST_CASE("duplicate_message_limit stops a VUID after N reports and announces the last",
          "[integration][report][passes-invalid-down]") {
  ApiSettings settings;
  settings.Add("duplicate_message_limit", "2");
  Fixture f(settings.Chain());
  vkkit::Device& device = f.device();
  vkkit::TriangleBuild build(device);
  f.monitor().Expect(kVuid, 2);
  RecordMisalignedBuilds(device, build, 4);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 2);
  CHECK(messages[0].text.find("last time") == std::string::npos);
  CHECK(messages[1].text.find("this will be the last time reporting it") != std::string::npos);
  build.Release(device);
}

TEST_CASE("message_id_filter mutes by suffix, by full name and by id", "[integration][report][passes-invalid-down]") {
  for (const char* filter : {"03710", kVuid, "0x63ff8904"}) {  // the last is kVuidId
    ApiSettings settings;
    settings.Add("message_id_filter", filter);
    Fixture f(settings.Chain());
    vkkit::Device& device = f.device();
    vkkit::TriangleBuild build(device);
    // Muted: nothing reported, so the callback cannot ask for a skip and the call goes down. It is recorded
    // but never submitted, so the driver never runs the misaligned build.
    build.UseScratchOffset(device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2);
    device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); }, /*submit=*/false);
    INFO("filter " << filter);
    CHECK(f.monitor().Verify() == "");
    build.Release(device);
  }
}

using asval_test_common::Printable;
using asval_test_common::TempReport;

// One misaligned build with the structure named blas_name, reported into a report file; its lines.
std::vector<std::string> ReportMisalignedBuild(const char* blas_name) {
  TempReport file;
  ApiSettings settings;
  settings.Add("report_file", file.path.c_str());
  {
    Fixture f(settings.Chain());
    vkkit::Device& device = f.device();
    vkkit::TriangleBuild build(device);
    device.SetName(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, reinterpret_cast<uint64_t>(build.blas.handle), blas_name);
    f.monitor().Expect(kVuid);
    RecordMisalignedBuilds(device, build, 1);
    CHECK(f.monitor().Verify() == "");
    build.Release(device);
  }
  return file.Lines();
}

// The one line of a report, parsed; the fields every finding has.
nlohmann::json ParseFinding(const std::vector<std::string>& lines) {
  REQUIRE(lines.size() == 1);
  INFO(Printable(lines[0]));
  REQUIRE(nlohmann::json::accept(lines[0]));
  const nlohmann::json finding = nlohmann::json::parse(lines[0]);
  CHECK(finding["severity"] == "error");
  CHECK(finding["vuid"] == kVuid);
  CHECK(finding["message_id"] == "0x63ff8904");
  CHECK(finding["function"] == "vkCmdBuildAccelerationStructuresKHR");
  CHECK(finding["location"] == "pInfos[0].scratchData.deviceAddress");
  CHECK_FALSE(finding["message"].get<std::string>().empty());
  CHECK(finding["spec_text"].get<std::string>().rfind("For each element of pInfos, its scratchData", 0) == 0);
  REQUIRE(finding["objects"].size() == 2);
  CHECK(finding["objects"][0]["type"] == "VkCommandBuffer");
  CHECK(finding["objects"][1]["type"] == "VkAccelerationStructureKHR");
  return finding;
}

TEST_CASE("report_file receives one JSON object per finding, names with quotes and control characters included",
          "[integration][report]") {
  const std::string name = "my \"BLAS\" \\ with\ttab, newline\n and \x01";
  const nlohmann::json finding = ParseFinding(ReportMisalignedBuild(name.c_str()));
  CHECK(finding["objects"][1]["name"] == name);
  CHECK_FALSE(finding["objects"][0].contains("name"));  // the command buffer has none
}

// A name that is not UTF-8 breaks the spec's rule for pObjectName, which lower layers may report: the call
// goes down, so the self-validation run leaves this test out.
TEST_CASE("report_file lines stay JSON when an object name is not UTF-8", "[integration][report][passes-invalid-down]") {
  const nlohmann::json finding = ParseFinding(ReportMisalignedBuild("\xff\xfe \"BLAS\""));
  // Each invalid byte becomes U+FFFD (EF BF BD in UTF-8); the rest of the name is kept.
  CHECK(finding["objects"][1]["name"] == "\xEF\xBF\xBD\xEF\xBF\xBD \"BLAS\"");
}

TEST_CASE("a malformed setting is reported as a warning at instance creation, not a crash", "[integration][report]") {
  ApiSettings settings;
  settings.Add("duplicate_message_limit", "many");
  settings.Add("no_such_setting", "1");
  Monitor* monitor = nullptr;
  std::vector<Message> messages;
  {
    Fixture f(settings.Chain());
    monitor = &f.monitor();
    messages = monitor->Take();
  }
  int warnings = 0;
  for (const Message& m : messages) {
    if (m.id_name == "ASVAL-Settings-Invalid" && m.severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
      ++warnings;
    }
  }
  CHECK(warnings == 2);
}

}  // namespace
}  // namespace asval_test

namespace asval_test {
namespace {

// Environment variables are read when the instance is created, and win over the API structure.
struct ScopedEnv {
  std::string name;
  ScopedEnv(const char* n, const char* value) : name(n) { setenv(n, value, 1); }
  ~ScopedEnv() { unsetenv(name.c_str()); }
};

TEST_CASE("settings from the environment win over VkLayerSettingsCreateInfoEXT",
          "[integration][report][passes-invalid-down]") {
  ApiSettings settings;
  settings.Add("duplicate_message_limit", "5");
  for (const char* name : {"VK_ASVAL_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT", "VK_AS_VALIDATION_DUPLICATE_MESSAGE_LIMIT",
                           "VK_DUPLICATE_MESSAGE_LIMIT"}) {
    ScopedEnv env(name, "1");
    Fixture f(settings.Chain());
    vkkit::Device& device = f.device();
    vkkit::TriangleBuild build(device);
    // Recorded, never submitted: with a limit of 1 the second build is not reported and so not skipped.
    build.UseScratchOffset(device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2);
    f.monitor().Expect(kVuid, 1);
    device.OneShot([&](VkCommandBuffer cb) {
      build.Record(device, cb);
      build.Record(device, cb);
    }, /*submit=*/false);
    INFO("variable " << name);
    CHECK(f.monitor().Verify() == "");
    build.Release(device);
  }
}

}  // namespace
}  // namespace asval_test

namespace asval_test {
namespace {

TEST_CASE("enabled_checks: a family left out is not checked", "[integration][report][passes-invalid-down]") {
  ApiSettings settings;
  settings.Add("enabled_checks", "features,handles,structure,addresses,aliasing,host,copies,history");
  Fixture f(settings.Chain());
  vkkit::Device& device = f.device();
  vkkit::TriangleBuild build(device);
  build.UseScratchOffset(device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2);
  device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); }, /*submit=*/false);
  CHECK(f.monitor().Verify() == "");
  build.Release(device);
}

}  // namespace
}  // namespace asval_test
