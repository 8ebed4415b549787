// Reporting: the debug-utils callback data, object names, duplicate limit, mute list, JSON report, and
// settings given through VkLayerSettingsCreateInfoEXT (declared here as the 1.3.239 headers lack it).
#define XXH_INLINE_ALL
#include <xxhash.h>

#include <catch2/catch_test_macros.hpp>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

#include "fixture.h"

namespace asval_test {
namespace {

constexpr const char* kVuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710";

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
  CHECK(static_cast<uint32_t>(m.id_number) == XXH32(kVuid, std::strlen(kVuid), 8));
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
  const char* filters[] = {"03710", kVuid, "0x0"};
  char hash[16];
  std::snprintf(hash, sizeof(hash), "0x%x", XXH32(kVuid, std::strlen(kVuid), 8));
  filters[2] = hash;
  for (const char* filter : filters) {
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

TEST_CASE("report_file receives one JSON object per finding", "[integration][report]") {
  char path[] = "/tmp/asval-report-XXXXXX";
  const int fd = mkstemp(path);
  REQUIRE(fd >= 0);
  close(fd);
  {
    ApiSettings settings;
    settings.Add("report_file", path);
    Fixture f(settings.Chain());
    vkkit::Device& device = f.device();
    vkkit::TriangleBuild build(device);
    f.monitor().Expect(kVuid);
    RecordMisalignedBuilds(device, build, 1);
    CHECK(f.monitor().Verify() == "");
    build.Release(device);
  }
  std::ifstream in(path);
  std::string line, all;
  int lines = 0;
  while (std::getline(in, line)) {
    ++lines;
    all = line;
  }
  std::remove(path);
  REQUIRE(lines == 1);
  CHECK(all.rfind("{\"severity\":\"error\",\"vuid\":\"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710\"", 0) == 0);
  CHECK(all.find("\"function\":\"vkCmdBuildAccelerationStructuresKHR\"") != std::string::npos);
  CHECK(all.find("\"location\":\"pInfos[0].scratchData.deviceAddress\"") != std::string::npos);
  CHECK(all.find("\"type\":\"VkAccelerationStructureKHR\"") != std::string::npos);
  CHECK(all.find("\"spec_text\":\"") != std::string::npos);
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
