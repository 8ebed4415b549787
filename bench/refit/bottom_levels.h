#pragma once
// The N bottom-level structures the benchmark refits every frame: one triangle geometry each (the shared grid
// mesh's indices, the structure's own slice of the moved positions), ALLOW_UPDATE, built once and then updated in
// place (src == dst). Every structure has its own scratch slice and its own span of one storage buffer, so no two
// builds of a frame touch the same memory and no barrier is needed between them.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "refit_options.h"
#include "vkkit.h"

namespace refit {

class BottomLevels {
 public:
  // positions: 3 floats per vertex, `vertices_per_mesh` per structure, structure after structure; indices: the
  // mesh's uint32 indices, shared by all.
  BottomLevels(vkkit::Device& device, const vkkit::Buffer& positions, const vkkit::Buffer& indices,
               uint32_t vertices_per_mesh, uint32_t triangles, uint32_t structures);
  ~BottomLevels();
  BottomLevels(const BottomLevels&) = delete;
  BottomLevels& operator=(const BottomLevels&) = delete;

  // Builds (BUILD) or refits in place (UPDATE) every structure, as `shape` says, then a barrier before the top
  // level reads them.
  void Record(VkCommandBuffer cb, VkBuildAccelerationStructureModeKHR mode, Shape shape);
  const std::vector<VkDeviceAddress>& addresses() const { return addresses_; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer storage_;
  vkkit::Buffer scratch_;
  std::vector<VkAccelerationStructureKHR> structures_;
  std::vector<VkDeviceAddress> addresses_;
  // Filled once: a frame's recording only sets the mode and the source.
  std::vector<VkAccelerationStructureGeometryKHR> geometries_;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos_;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges_;
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> range_pointers_;
};

}  // namespace refit
