#pragma once
// The one top-level structure over all refit bottom-level structures: one instance each, on a grid, written
// once by the host; built in the first frame and updated in place (ALLOW_UPDATE) after the refits every frame,
// as an engine's scene structure is.
#include <vulkan/vulkan.h>

#include <vector>

#include "vkkit.h"

namespace refit {

class TopLevel {
 public:
  TopLevel(vkkit::Device& device, const std::vector<VkDeviceAddress>& bottom_levels);
  ~TopLevel();
  TopLevel(const TopLevel&) = delete;
  TopLevel& operator=(const TopLevel&) = delete;

  // BUILD, or UPDATE in place.
  void Record(VkCommandBuffer cb, VkBuildAccelerationStructureModeKHR mode);

 private:
  vkkit::Device& device_;
  vkkit::Buffer instances_;  // host-visible: written once, read by every build
  vkkit::Buffer storage_;
  vkkit::Buffer scratch_;
  VkAccelerationStructureKHR structure_ = VK_NULL_HANDLE;
  VkAccelerationStructureGeometryKHR geometry_{};
  VkAccelerationStructureBuildGeometryInfoKHR info_{};
  VkAccelerationStructureBuildRangeInfoKHR range_{};
};

}  // namespace refit
