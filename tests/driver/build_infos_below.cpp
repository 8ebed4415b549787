#include "build_infos_below.h"

#include <cstring>

#include "driver_dispatch.h"

namespace asval_test_driver {
namespace {

constexpr VkBuildAccelerationStructureFlagsKHR kMotionFlags = VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV;
constexpr VkBuildAccelerationStructureFlagsKHR kOpacityMicromapFlags =
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT |
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_DISABLE_OPACITY_MICROMAPS_EXT |
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_DATA_UPDATE_EXT;

}  // namespace

BuildInfosBelow::BuildInfosBelow(const DeviceData& device, uint32_t count,
                                 const VkAccelerationStructureBuildGeometryInfoKHR* infos)
    : infos_(infos) {
  if (!device.motion_blur && !device.opacity_micromap) return;
  const VkBuildAccelerationStructureFlagsKHR removed_flags =
      (device.motion_blur ? kMotionFlags : 0) | (device.opacity_micromap ? kOpacityMicromapFlags : 0);
  // A type of a disabled extension is not valid in the chain: taking it out too changes nothing for a valid build.
  const auto motion_triangles = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV;
  const auto opacity_micromap = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT;
  copies_.assign(infos, infos + count);
  geometries_.resize(count);  // not resized again: the arrays the copies point to stay where they are
  for (uint32_t i = 0; i < count; ++i) {
    VkAccelerationStructureBuildGeometryInfoKHR& info = copies_[i];
    info.flags &= ~removed_flags;
    std::vector<VkAccelerationStructureGeometryKHR>& geometries = geometries_[i];
    for (uint32_t g = 0; g < info.geometryCount; ++g) {
      geometries.push_back(info.pGeometries != nullptr ? info.pGeometries[g] : *info.ppGeometries[g]);
      VkAccelerationStructureGeometryKHR& geometry = geometries.back();
      if (geometry.geometryType != VK_GEOMETRY_TYPE_TRIANGLES_KHR) continue;
      chains_.emplace_back(geometry.geometry.triangles.pNext,
                           std::initializer_list<VkStructureType>{motion_triangles, opacity_micromap});
      geometry.geometry.triangles.pNext = chains_.back().head();
    }
    info.pGeometries = geometries.empty() ? nullptr : geometries.data();
    info.ppGeometries = nullptr;
  }
  infos_ = copies_.data();
}

namespace {

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructuresKHR(
    VkCommandBuffer command_buffer, uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
    const VkAccelerationStructureBuildRangeInfoKHR* const* ranges) {
  DeviceData* device = FindDevice(command_buffer);
  const BuildInfosBelow below(*device, count, infos);
  device->vk.CmdBuildAccelerationStructuresKHR(command_buffer, count, below.get(), ranges);
}

}  // namespace

PFN_vkVoidFunction BuildInfosBelowFunction(const char* name) {
  if (std::strcmp(name, "vkCmdBuildAccelerationStructuresKHR") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&CmdBuildAccelerationStructuresKHR);
  }
  return nullptr;
}

}  // namespace asval_test_driver
