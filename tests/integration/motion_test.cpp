// VK_NV_ray_tracing_motion_blur in the KHR builds (family "handles"): a motion build writes a structure created for
// motion, and a structure created for motion is built with motion (flags-04928, dstAccelerationStructure-04927).
// Through the loader on the test driver, which exposes the extension over lavapipe and passes motion builds down
// without it (tests/driver/motion_blur.h).
#include <catch2/catch_test_macros.hpp>
#include <cstring>

#include "build_extension_helpers.h"
#include "history_helpers.h"
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

namespace asval_test {
namespace {

// Two triangles of a motion build: their vertices at time 0 and at time 1 in host-visible buffers of their own, a
// structure created for motion, scratch; builds and updates in place, each submitted and waited for (the capture's
// findings are reported in the wait).
class MotionRefit {
 public:
  explicit MotionRefit(vkkit::Device& device, bool motion = true)
      : device_(device), motion_(motion), structure_(device, motion), commands_(device) {
    for (vkkit::Buffer* b : {&at_0_, &at_1_}) {
      *b = device.CreateBuffer(256, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    }
    scratch_ = device.CreateBuffer(1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    Write(at_0_, 0.0f);
    Write(at_1_, 0.0f);
  }
  ~MotionRefit() {
    for (vkkit::Buffer* b : {&at_0_, &at_1_, &scratch_}) device_.Destroy(*b);
  }

  // Six vertices (two unit right triangles) moved by dx along X.
  static void Write(vkkit::Buffer& buffer, float dx) {
    float v[18];
    const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    for (int k = 0; k < 6; ++k) {
      v[3 * k + 0] = corner[k % 3][0] + dx;
      v[3 * k + 1] = corner[k % 3][1];
      v[3 * k + 2] = static_cast<float>(k / 3);
    }
    std::memcpy(buffer.mapped, v, sizeof(v));
  }
  // Triangle t's first vertex X at time 1 made NaN: the triangle is inactive (any of its six vertices' X).
  void NanAtTime1(uint32_t t) {
    const uint32_t nan = 0x7fc00000u;
    std::memcpy(static_cast<char*>(at_1_.mapped) + 36 * t, &nan, sizeof(nan));
  }
  vkkit::Buffer& at_1() { return at_1_; }

  // A build (or an update in place) of both triangles, submitted and waited for; the layer's result.
  VkResult Run(bool update) {
    VkAccelerationStructureGeometryMotionTrianglesDataNV time_1{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
    time_1.vertexData.deviceAddress = at_1_.address;
    VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    VkAccelerationStructureGeometryTrianglesDataKHR& t = geometry.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.pNext = &time_1;  // chained either way: read only by a motion build
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexData.deviceAddress = at_0_.address;
    t.vertexStride = 12;
    t.maxVertex = 5;
    t.indexType = VK_INDEX_TYPE_NONE_KHR;
    VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
                 (motion_ ? VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV : 0);
    info.mode =
        update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.srcAccelerationStructure = update ? structure_.handle() : VK_NULL_HANDLE;
    info.dstAccelerationStructure = structure_.handle();
    info.geometryCount = 1;
    info.pGeometries = &geometry;
    info.scratchData.deviceAddress = scratch_.address;
    const VkAccelerationStructureBuildRangeInfoKHR range{2, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
    VkCommandBuffer cb = commands_.Begin();
    device_.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
    commands_.End(cb);
    return commands_.Submit(cb);
  }

 private:
  vkkit::Device& device_;
  bool motion_;
  MotionStructure structure_;
  Commands commands_;
  vkkit::Buffer at_0_, at_1_, scratch_;
};

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
