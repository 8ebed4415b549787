// Extensions of the KHR builds that no local driver has, on asval's test driver (which exposes them over lavapipe and
// passes the builds down without them: tests/driver): motion blur (VK_NV_ray_tracing_motion_blur: a motion build
// writes a structure created for motion) and opacity micromaps (VK_EXT_opacity_micromap: the micromap a triangles
// geometry chains), each fault with a valid program beside it.
#include "build_extension_helpers.h"
#include "corpus.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::Micromap;
using asval_test::MotionStructure;
using asval_test::OpacityFromSpecialIndices;
using asval_test::Scene;
using asval_test::SpecialIndexBuffer;

// A one-triangle build into a structure created for motion (or not), with the motion flag and a second vertex set
// (or not).
void MotionBuild(vkkit::Device& device, bool created_for_motion, bool motion_build) {
  Scene scene(device);
  const MotionStructure dst(device, created_for_motion);
  VkAccelerationStructureGeometryMotionTrianglesDataNV second{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
  second.vertexData.deviceAddress = scene.Address(Scene::kVertices);
  VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
  if (motion_build) geometry.geometry.triangles.pNext = &second;
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
  info.pGeometries = &geometry;
  if (motion_build) info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV;
  scene.Prepare(info, {1});
  info.dstAccelerationStructure = dst.handle();
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({info}, {&range});
}

constexpr const char* kMotion = "motion-blur";
constexpr const char* kMicromap = "opacity-micromap";

CORPUS_CASE_ON_TEST_DRIVER(MotionBuildIntoStaticStructure, "motion-build-into-structure-created-without-motion",
                           "handles", kMotion,
                           "a motion build of motion triangles into a structure created without CREATE_MOTION_BIT_NV",
                           {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-04928"}) {
  MotionBuild(device, false, true);
}

CORPUS_CASE_ON_TEST_DRIVER(MotionBuildValid, "motion-build-into-structure-created-for-motion", "handles", kMotion,
                           "a motion build of motion triangles into a structure created for motion", {}) {
  MotionBuild(device, true, true);
}

// A one-triangle build whose opacity comes from a micromap, indexed by 32-bit special indices `stride` bytes apart.
void MicromapBuild(vkkit::Device& device, VkDeviceSize stride) {
  Scene scene(device);
  vkkit::Buffer indices = SpecialIndexBuffer(device);
  const Micromap micromap(device);
  VkAccelerationStructureTrianglesOpacityMicromapEXT opacity = OpacityFromSpecialIndices(indices, micromap, stride);
  VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
  geometry.geometry.triangles.pNext = &opacity;
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
  info.pGeometries = &geometry;
  scene.Prepare(info, {1});
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({info}, {&range});
  device.Destroy(indices);
}

CORPUS_CASE_ON_TEST_DRIVER(MicromapOddStride, "micromap-index-stride-not-a-multiple-of-the-index-size", "structure",
                           kMicromap, "a triangle's micromap indices are 32-bit, 6 bytes apart",
                           {"VUID-VkAccelerationStructureTrianglesOpacityMicromapEXT-indexType-10722"}) {
  MicromapBuild(device, 6);
}

CORPUS_CASE_ON_TEST_DRIVER(MicromapValid, "micromap-special-indices", "structure", kMicromap,
                           "a triangle's micromap indices are 32-bit special indices, 4 bytes apart", {}) {
  MicromapBuild(device, 4);
}

}  // namespace

namespace {

using asval_test::MotionRefit;

CORPUS_CASE_ON_TEST_DRIVER(MotionRefitDeactivates, "motion-refit-makes-triangle-inactive-at-time-1", "history", kMotion,
                           "a motion refit whose vertices at time 1 give a triangle a NaN X, which makes it inactive",
                           {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664"}) {
  MotionRefit refit(device);
  refit.Run(false);
  refit.NanAtTime1(1);
  refit.Run(true);
}

CORPUS_CASE_ON_TEST_DRIVER(MotionRefitMoves, "motion-refit-moves-vertices-at-time-1", "history", kMotion,
                           "motion refits that move the vertices at time 1 frame after frame", {}) {
  MotionRefit refit(device);
  refit.Run(false);
  for (float dx : {0.5f, 1.0f, 2.0f}) {
    MotionRefit::Write(refit.at_1(), dx);
    refit.Run(true);
  }
}

}  // namespace
