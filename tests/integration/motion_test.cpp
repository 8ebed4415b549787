// VK_NV_ray_tracing_motion_blur in the KHR builds (family "handles"): a motion build writes a structure created for
// motion, and a structure created for motion is built with motion (flags-04928, dstAccelerationStructure-04927).
// Through the loader on the test driver, which exposes the extension over lavapipe and passes motion builds down
// without it (tests/driver/motion_blur.h).
#include <catch2/catch_test_macros.hpp>
#include <cstring>

#include "build_extension_helpers.h"
#include "history_helpers.h"  // HistoryFixture
#include "on_test_driver.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

// A one-triangle build into `dst`, with the motion flag and the second vertex set (the scene's vertices again) when
// `motion`. `motion_data` must outlive the recording.
VkAccelerationStructureBuildGeometryInfoKHR TriangleBuild(
    Scene& scene, VkAccelerationStructureGeometryKHR& geometry,
    VkAccelerationStructureGeometryMotionTrianglesDataNV& motion_data, VkAccelerationStructureKHR dst, bool motion) {
  geometry = scene.Triangles();
  if (motion) {
    motion_data.vertexData.deviceAddress = scene.Address(Scene::kVertices);
    geometry.geometry.triangles.pNext = &motion_data;
  }
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
  info.pGeometries = &geometry;
  scene.Prepare(info, {1});
  info.dstAccelerationStructure = dst;
  if (motion) info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV;
  return info;
}

TEST_CASE(
    "motion: a motion build into a structure created without CREATE_MOTION_BIT_NV, and a build without the "
    "motion flag into one created with it, are reported (flags-04928, dstAccelerationStructure-04927)",
    "[integration][handles][motion][test-driver][newer-input]") {
  const OnTestDriver driver;
  const MotionBlurDevice motion_device;
  CheckFixture f("handles", motion_device.options);
  vkkit::Device& device = f.device();
  Scene scene(device);
  MotionStructure plain(device, false), moving(device, true);
  VkAccelerationStructureGeometryKHR g0, g1;
  VkAccelerationStructureGeometryMotionTrianglesDataNV m0{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
  VkAccelerationStructureGeometryMotionTrianglesDataNV m1 = m0;
  const VkAccelerationStructureBuildGeometryInfoKHR infos[2] = {TriangleBuild(scene, g0, m0, plain.handle(), true),
                                                                TriangleBuild(scene, g1, m1, moving.handle(), false)};
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges[2] = {&range, &range};
  f.monitor().Expect("VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-04928");
  f.monitor().Expect("VUID-VkAccelerationStructureBuildGeometryInfoKHR-dstAccelerationStructure-04927");
  device.OneShot([&](VkCommandBuffer cb) {
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &infos[0], &ranges[0]);
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &infos[1], &ranges[1]);
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "motion valid twin: a motion build of motion triangles into a structure created for motion, and a plain "
    "build into a plain structure, stay silent and execute",
    "[integration][handles][motion][test-driver][valid][newer-input]") {
  const OnTestDriver driver;
  const MotionBlurDevice motion_device;
  CheckFixture f(nullptr, motion_device.options);
  vkkit::Device& device = f.device();
  Scene scene(device);
  MotionStructure plain(device, false), moving(device, true);
  VkAccelerationStructureGeometryKHR g0, g1;
  VkAccelerationStructureGeometryMotionTrianglesDataNV m0{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
  VkAccelerationStructureGeometryMotionTrianglesDataNV m1 = m0;
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow(
      {TriangleBuild(scene, g0, m0, moving.handle(), true), TriangleBuild(scene, g1, m1, plain.handle(), false)},
      {&range, &range});
  CHECK(f.monitor().Verify() == "");
}

constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";

TEST_CASE(
    "motion capture: a motion refit whose vertices at time 1 make an active triangle inactive is reported "
    "(pInfos-03664)",
    "[integration][capture][motion][test-driver][newer-input]") {
  const OnTestDriver driver;
  const MotionBlurDevice motion_device;
  HistoryFixture f(nullptr, {}, motion_device.options);
  MotionRefit refit(f.device());
  REQUIRE(refit.Run(false) == VK_SUCCESS);
  refit.NanAtTime1(1);
  f.monitor().Expect(kBecameInactive);
  refit.Run(true);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "motion capture valid twin: motion refits that move the vertices at time 1 stay silent, and a build without "
    "the motion flag does not read the motion vertices it chains",
    "[integration][capture][motion][test-driver][valid][newer-input]") {
  const OnTestDriver driver;
  const MotionBlurDevice motion_device;
  HistoryFixture f(nullptr, {}, motion_device.options);
  {
    MotionRefit refit(f.device());
    REQUIRE(refit.Run(false) == VK_SUCCESS);
    for (float dx : {0.5f, 1.0f, 2.0f}) {
      MotionRefit::Write(refit.at_1(), dx);
      CHECK(refit.Run(true) == VK_SUCCESS);
    }
  }
  {
    MotionRefit plain(f.device(), false);
    REQUIRE(plain.Run(false) == VK_SUCCESS);
    plain.NanAtTime1(1);  // not read: not a motion build
    CHECK(plain.Run(true) == VK_SUCCESS);
  }
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test

namespace asval_test {
namespace {

// The motion device with accelerationStructureHostCommands (the test driver executes host builds).
struct HostMotionDevice {
  HostMotionDevice() { base.options.host_commands = true; }
  MotionBlurDevice base;
  const vkkit::DeviceOptions& options() const { return base.options; }
};

TEST_CASE(
    "motion capture: a host motion refit whose vertices at time 1 make an active triangle inactive is reported "
    "when called (vkBuildAccelerationStructuresKHR-pInfos-03664)",
    "[integration][capture][host][motion][test-driver][newer-input]") {
  const OnTestDriver driver;
  const HostMotionDevice motion_device;
  HistoryFixture f(nullptr, {}, motion_device.options());
  MotionRefit refit(f.device());
  REQUIRE(refit.RunOnHost(false) == VK_SUCCESS);
  refit.NanAtTime1(1);
  f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03664");
  CHECK(refit.RunOnHost(true) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("motion capture valid twin: host motion refits that move the vertices at time 1 stay silent and execute",
          "[integration][capture][host][motion][test-driver][valid][newer-input]") {
  const OnTestDriver driver;
  const HostMotionDevice motion_device;
  HistoryFixture f(nullptr, {}, motion_device.options());
  MotionRefit refit(f.device());
  REQUIRE(refit.RunOnHost(false) == VK_SUCCESS);
  for (float dx : {0.5f, 1.0f, 2.0f}) {
    MotionRefit::Write(refit.at_1(), dx);
    CHECK(refit.RunOnHost(true) == VK_SUCCESS);
  }
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
