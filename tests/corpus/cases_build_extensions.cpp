// Extensions of the KHR builds that no local driver has, on asval's test driver (which exposes them over lavapipe and
// passes the builds down without them: tests/driver): motion blur (VK_NV_ray_tracing_motion_blur: a motion build
// writes a structure created for motion) and opacity micromaps (VK_EXT_opacity_micromap: the micromap a triangles
// geometry chains), each fault with a valid program beside it.
#include <cstring>

#include "corpus.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::Scene;

// A bottom-level structure of 64 KiB, created for motion or not.
VkAccelerationStructureKHR NewStructure(vkkit::Device& device, vkkit::Buffer& storage, bool motion) {
  storage = device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  VkAccelerationStructureMotionInfoNV motion_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MOTION_INFO_NV};
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.pNext = motion ? &motion_info : nullptr;
  info.createFlags = motion ? VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV : 0;
  info.buffer = storage.buffer;
  info.size = storage.size;
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
  vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &info, nullptr, &handle),
               "vkCreateAccelerationStructureKHR");
  return handle;
}

// A one-triangle build into a structure created for motion (or not), with the motion flag and a second vertex set
// (or not).
void MotionBuild(vkkit::Device& device, bool created_for_motion, bool motion_build) {
  Scene scene(device);
  vkkit::Buffer storage;
  const VkAccelerationStructureKHR dst = NewStructure(device, storage, created_for_motion);
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
  info.dstAccelerationStructure = dst;
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({info}, {&range});
  device.DestroyAccelerationStructureKHR(device.handle(), dst, nullptr);
  device.Destroy(storage);
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
  vkkit::Buffer indices =
      device.CreateBuffer(256, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  const uint32_t opaque = static_cast<uint32_t>(VK_OPACITY_MICROMAP_SPECIAL_INDEX_FULLY_OPAQUE_EXT);
  std::memcpy(indices.mapped, &opaque, sizeof(opaque));
  vkkit::Buffer storage = device.CreateBuffer(4096, VK_BUFFER_USAGE_MICROMAP_STORAGE_BIT_EXT);
  auto create = reinterpret_cast<PFN_vkCreateMicromapEXT>(vkGetDeviceProcAddr(device.handle(), "vkCreateMicromapEXT"));
  auto destroy =
      reinterpret_cast<PFN_vkDestroyMicromapEXT>(vkGetDeviceProcAddr(device.handle(), "vkDestroyMicromapEXT"));
  VkMicromapCreateInfoEXT create_info{VK_STRUCTURE_TYPE_MICROMAP_CREATE_INFO_EXT};
  create_info.buffer = storage.buffer;
  create_info.size = storage.size;
  create_info.type = VK_MICROMAP_TYPE_OPACITY_MICROMAP_EXT;
  VkMicromapEXT micromap = VK_NULL_HANDLE;
  vkkit::Check(create(device.handle(), &create_info, nullptr, &micromap), "vkCreateMicromapEXT");
  VkAccelerationStructureTrianglesOpacityMicromapEXT opacity{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT};
  opacity.indexType = VK_INDEX_TYPE_UINT32;
  opacity.indexBuffer.deviceAddress = indices.address;
  opacity.indexStride = stride;
  opacity.micromap = micromap;
  VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
  geometry.geometry.triangles.pNext = &opacity;
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
  info.pGeometries = &geometry;
  scene.Prepare(info, {1});
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({info}, {&range});
  destroy(device.handle(), micromap, nullptr);
  device.Destroy(storage);
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
