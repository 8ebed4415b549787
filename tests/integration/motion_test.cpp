// VK_NV_ray_tracing_motion_blur in the KHR builds (family "handles"): a motion build writes a structure created for
// motion, and a structure created for motion is built with motion (flags-04928, dstAccelerationStructure-04927).
// Through the loader on the test driver, which exposes the extension over lavapipe and passes motion builds down
// without it (tests/driver/motion_blur.h).
#include <catch2/catch_test_macros.hpp>

#include "build_extension_helpers.h"
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

}  // namespace
}  // namespace asval_test
