// VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710: scratch address alignment, and its valid twins.
#include <catch2/catch_test_macros.hpp>

#include "fixture.h"

namespace asval_test {
namespace {

constexpr const char* kVuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710";

TEST_CASE("03710: a misaligned scratch address is reported", "[integration][03710]") {
  Fixture f;
  vkkit::Device& device = f.device();
  const uint32_t alignment = device.as_properties().minAccelerationStructureScratchOffsetAlignment;
  REQUIRE(alignment > 1);
  vkkit::TriangleBuild build(device);
  build.UseScratchOffset(alignment / 2);
  f.monitor().Expect(kVuid);
  device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); });
  CHECK(f.monitor().Verify() == "");
  build.Release(device);
}

TEST_CASE("03710: every misaligned info of one call is reported, aligned ones are not", "[integration][03710]") {
  Fixture f;
  vkkit::Device& device = f.device();
  const uint32_t alignment = device.as_properties().minAccelerationStructureScratchOffsetAlignment;
  vkkit::TriangleBuild a(device), b(device), c(device);
  a.UseScratchOffset(1);
  b.UseScratchOffset(alignment);  // aligned, not at the buffer's start
  c.UseScratchOffset(alignment + 4);
  VkAccelerationStructureBuildGeometryInfoKHR infos[3] = {a.info, b.info, c.info};
  infos[0].pGeometries = &a.geometry;
  infos[1].pGeometries = &b.geometry;
  infos[2].pGeometries = &c.geometry;
  const VkAccelerationStructureBuildRangeInfoKHR* ranges[3] = {&a.range, &b.range, &c.range};
  f.monitor().Expect(kVuid, 2);
  device.OneShot([&](VkCommandBuffer cb) { device.CmdBuildAccelerationStructuresKHR(cb, 3, infos, ranges); });
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 2);
  CHECK(messages[0].text.find("pInfos[0].scratchData.deviceAddress") != std::string::npos);
  CHECK(messages[1].text.find("pInfos[2].scratchData.deviceAddress") != std::string::npos);
  a.Release(device);
  b.Release(device);
  c.Release(device);
}

TEST_CASE("03710 valid twin: aligned scratch addresses stay silent", "[integration][03710]") {
  Fixture f;
  vkkit::Device& device = f.device();
  const uint32_t alignment = device.as_properties().minAccelerationStructureScratchOffsetAlignment;
  vkkit::TriangleBuild build(device, 256);
  // At the buffer's start, at the device's alignment, and at the 128 bytes real apps use for every slice.
  for (VkDeviceSize offset : {VkDeviceSize{0}, VkDeviceSize{alignment}, VkDeviceSize{128}}) {
    build.UseScratchOffset(offset);
    device.OneShot([&](VkCommandBuffer cb) { build.Record(device, cb); });
    INFO("scratch offset " << offset);
    CHECK(f.monitor().Verify() == "");
  }
  build.Release(device);
}

}  // namespace
}  // namespace asval_test
