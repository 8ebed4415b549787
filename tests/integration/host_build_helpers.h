#pragma once
// A host build of one geometry of the scene's kinds, with host pointers everywhere (family "host" tests).
#include <vector>

#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace asval_test {

// A valid-looking host build of one geometry: host pointers everywhere, the destination from the scene.
struct HostBuild {
  float vertices[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  uint32_t indices[3] = {0, 1, 2};
  VkAabbPositionsKHR box = {0, 0, 0, 1, 1, 1};
  VkAccelerationStructureInstanceKHR instance{};
  std::vector<unsigned char> scratch = std::vector<unsigned char>(1 << 16);
  VkAccelerationStructureGeometryKHR geometry{};
  VkAccelerationStructureBuildGeometryInfoKHR info{};
  VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};

  HostBuild(Scene& scene, VkAccelerationStructureGeometryKHR g) : geometry(g) {
    switch (geometry.geometryType) {
      case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
        geometry.geometry.triangles.vertexData.hostAddress = vertices;
        geometry.geometry.triangles.indexData.hostAddress = indices;
        break;
      case VK_GEOMETRY_TYPE_AABBS_KHR:
        geometry.geometry.aabbs.data.hostAddress = &box;
        break;
      default:
        instance.mask = 0xff;
        instance.accelerationStructureReference = reinterpret_cast<uint64_t>(scene.blas());
        geometry.geometry.instances.data.hostAddress = &instance;
        break;
    }
    const auto type = geometry.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR
                          ? VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR
                          : VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info = Scene::Info(type, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
    info.scratchData.hostAddress = scratch.data();
  }
  void Call(vkkit::Device& device) { CallHostBuild(device, {info}, {&range}); }
};

}  // namespace asval_test
