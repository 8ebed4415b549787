// VK_NV_ray_tracing_motion_blur in the KHR builds (family "handles"): a motion build writes a structure created for
// motion, and a structure created for motion is built with motion (flags-04928, dstAccelerationStructure-04927).
// Through the loader on the test driver, which exposes the extension over lavapipe and passes motion builds down
// without it (tests/driver/motion_blur.h).
#include <catch2/catch_test_macros.hpp>

#include "on_test_driver.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

struct MotionDevice {
  MotionDevice() {
    // The extension requires VK_KHR_ray_tracing_pipeline (vkkit enables ray queries on lavapipe, which has them).
    options.extensions.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
    options.extensions.push_back(VK_NV_RAY_TRACING_MOTION_BLUR_EXTENSION_NAME);
    features.rayTracingMotionBlur = VK_TRUE;
    options.features = &features;
  }
  VkPhysicalDeviceRayTracingMotionBlurFeaturesNV features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV};
  vkkit::DeviceOptions options;
};

// A bottom-level structure of 64 KiB created with or without CREATE_MOTION_BIT_NV; destroyed with the object.
class MotionStructure {
 public:
  MotionStructure(vkkit::Device& device, bool motion) : device_(device) {
    storage_ = device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    VkAccelerationStructureMotionInfoNV motion_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MOTION_INFO_NV};
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.pNext = motion ? &motion_info : nullptr;
    info.createFlags = motion ? VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV : 0;
    info.buffer = storage_.buffer;
    info.size = storage_.size;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &info, nullptr, &handle_),
                 "vkCreateAccelerationStructureKHR");
  }
  ~MotionStructure() {
    device_.DestroyAccelerationStructureKHR(device_.handle(), handle_, nullptr);
    device_.Destroy(storage_);
  }
  VkAccelerationStructureKHR handle() const { return handle_; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer storage_;
  VkAccelerationStructureKHR handle_ = VK_NULL_HANDLE;
};

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
  MotionDevice motion_device;
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
  MotionDevice motion_device;
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
