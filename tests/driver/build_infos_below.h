#pragma once
// The acceleration-structure build infos the driver below gets, with what the test driver's added extensions put in
// them taken out, for every path that builds or sizes (vkCmdBuildAccelerationStructuresKHR, the host builds of
// host_commands.h, the indirect builds of indirect_builds.h, vkGetAccelerationStructureBuildSizesKHR):
// - VK_NV_ray_tracing_motion_blur enabled (motion_blur.h): flags without VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV,
//   each triangles geometry's pNext without VkAccelerationStructureGeometryMotionTrianglesDataNV;
// - VK_EXT_opacity_micromap enabled (opacity_micromap.h): flags without the three opacity-micromap bits
//   (ALLOW_OPACITY_MICROMAP_UPDATE, ALLOW_DISABLE_OPACITY_MICROMAPS, ALLOW_OPACITY_MICROMAP_DATA_UPDATE), each
//   triangles geometry's pNext without VkAccelerationStructureTrianglesOpacityMicromapEXT.
// A device that enabled neither gets the application's infos as they are.
#include <vulkan/vulkan.h>

#include <vector>

#include "chain_edits.h"

namespace asval_test_driver {

struct DeviceData;

// The application's infos where the device enabled none of the extensions above, else copies without their flags and
// structures, their geometries copied into arrays of their own (pGeometries, whichever the application used). The
// chains in them are the application's structures (ChainWithout copies none of a triangles chain), so a copy of these
// infos that outlives this object (an indirect build's) is valid as long as theirs. The application's infos, arrays
// and chains stay as it gave them.
class BuildInfosBelow {
 public:
  BuildInfosBelow(const DeviceData& device, uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos);
  BuildInfosBelow(const BuildInfosBelow&) = delete;
  BuildInfosBelow& operator=(const BuildInfosBelow&) = delete;

  const VkAccelerationStructureBuildGeometryInfoKHR* get() const { return infos_; }

 private:
  const VkAccelerationStructureBuildGeometryInfoKHR* infos_;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> copies_;
  std::vector<std::vector<VkAccelerationStructureGeometryKHR>> geometries_;
  std::vector<ChainWithout> chains_;
};

// vkCmdBuildAccelerationStructuresKHR through BuildInfosBelow, for a device that enabled one of the extensions above
// (elsewhere the name goes down the chain), or nullptr for any other name.
PFN_vkVoidFunction BuildInfosBelowFunction(const char* name);

}  // namespace asval_test_driver
