// Family "host" on asval's test driver (docs/testing.md): host builds that reach a driver which executes them.
// The layers of the run (asval, and the Khronos layer in self-validation runs) sit above the test driver.
#include <catch2/catch_test_macros.hpp>
#include <cstring>

#include "host_build_helpers.h"
#include "on_test_driver.h"

namespace asval_test {
namespace {

// What the device says of the structure once the host build has run: a built structure has a serialized size.
uint64_t SerializedSize(vkkit::Device& device, VkAccelerationStructureKHR structure) {
  auto write = reinterpret_cast<PFN_vkWriteAccelerationStructuresPropertiesKHR>(
      vkGetDeviceProcAddr(device.handle(), "vkWriteAccelerationStructuresPropertiesKHR"));
  uint64_t size = 0;
  vkkit::Check(write(device.handle(), 1, &structure, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                     sizeof(size), &size, sizeof(size)),
               "vkWriteAccelerationStructuresPropertiesKHR");
  return size;
}

TEST_CASE(
    "03581 valid twin on the test driver: host builds with accelerationStructureHostCommands stay silent "
    "and execute",
    "[integration][host][test-driver][valid]") {
  const OnTestDriver driver;
  CheckFixture f("host", OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  Scene scene(device);
  for (const auto& geometry : {scene.Triangles(), scene.IndexedTriangles(VK_INDEX_TYPE_UINT32),
                               scene.IndexedTriangles(VK_INDEX_TYPE_UINT16), scene.Aabbs(), scene.Instances()}) {
    HostBuild build(scene, geometry);
    REQUIRE(CallHostBuild(device, {build.info}, {&build.range}) == VK_SUCCESS);
    CHECK(SerializedSize(device, build.info.dstAccelerationStructure) != 0);
  }
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("03581 on the test driver: a host build on a device that did not enable the feature is reported",
          "[integration][host][test-driver][03581]") {
  const OnTestDriver driver;
  CheckFixture f("features");  // the driver offers host commands; this device does not enable them
  vkkit::Device& device = f.device();
  Scene scene(device);
  HostBuild build(scene, scene.Triangles());
  f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581");
  build.Call(device);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "pInfos-03722 / 03723 / 03724 on the test driver: host builds of, from or over structures on memory that is "
    "not host-visible are reported",
    "[integration][host][test-driver][03722][03723][03724]") {
  const OnTestDriver driver;
  CheckFixture f("host", OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  Scene scene(device);
  const DeviceLocalStructure device_local(device, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 1 << 16);
  SECTION("03722: the destination") {
    HostBuild build(scene, scene.Triangles());
    build.info.dstAccelerationStructure = device_local.handle();
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03722");
    build.Call(device);
  }
  SECTION("03723: an update's source") {
    HostBuild build(scene, scene.Triangles());
    build.info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
    build.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    build.info.srcAccelerationStructure = device_local.handle();
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03723");
    build.Call(device);
  }
  SECTION("03724: a structure an instance references") {
    HostBuild build(scene, scene.Instances());
    build.instance.accelerationStructureReference = reinterpret_cast<uint64_t>(device_local.handle());
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03724");
    build.Call(device);
  }
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test

namespace asval_test {
namespace {

constexpr const char* k03676Host = "VUID-vkBuildAccelerationStructuresKHR-ppBuildRangeInfos-03676";

TEST_CASE("ppBuildRangeInfos-03676 on the test driver: a host build whose ppBuildRangeInfos[i] is NULL for an info "
          "with geometries is reported",
          "[integration][structure][test-driver][03676]") {
  const OnTestDriver driver;
  CheckFixture f("structure", OnTestDriver::HostCommands());
  Scene scene(f.device());
  HostBuild build(scene, scene.Triangles());
  f.monitor().Expect(k03676Host);
  CallHostBuild(f.device(), {build.info}, {nullptr});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("ppBuildRangeInfos-03676 valid twin on the test driver: host builds whose infos with geometries have "
          "their range infos stay silent and execute",
          "[integration][structure][test-driver][valid]") {
  const OnTestDriver driver;
  CheckFixture f("structure", OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  Scene scene(device);
  HostBuild first(scene, scene.Triangles());
  HostBuild second(scene, scene.Aabbs());
  REQUIRE(CallHostBuild(device, {first.info, second.info}, {&first.range, &second.range}) == VK_SUCCESS);
  CHECK(SerializedSize(device, first.info.dstAccelerationStructure) != 0);
  CHECK(SerializedSize(device, second.info.dstAccelerationStructure) != 0);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
