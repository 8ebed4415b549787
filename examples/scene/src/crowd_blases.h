#pragma once
// --refits N: N more bottom-level structures refit every frame, each as its own vkCmdBuildAccelerationStructuresKHR,
// the way engines refit hundreds of skinned characters or deforming props, each where it is animated (issue 27;
// the benchmark of that case is bench/refit). Each is a copy of the blob (the blob's animated vertices and indices),
// with its own storage and its own scratch slice, built with the deforming structures in frame 0 and refit in place
// in every later frame. They are not instanced in the top level: the image stays the same.
#include <cstdint>
#include <vector>

#include "build_input.h"
#include "deforming_blases.h"
#include "gpu.h"

namespace scene {

class CrowdBlases {
 public:
  CrowdBlases(Gpu& gpu, const DeformingBlases& deforming, uint32_t count);
  ~CrowdBlases();
  CrowdBlases(const CrowdBlases&) = delete;
  CrowdBlases& operator=(const CrowdBlases&) = delete;

  uint32_t count() const { return static_cast<uint32_t>(structures_.size()); }
  // One call per structure (BUILD, or UPDATE in place), reading the vertices written in frames of this parity;
  // nothing when count() is 0. The caller's animate barrier comes before.
  void RecordBuilds(VkCommandBuffer cb, uint32_t parity, VkBuildAccelerationStructureModeKHR mode) const;

 private:
  Gpu& gpu_;
  const DeformingBlases& deforming_;
  std::vector<AccelerationStructure> structures_;
  Buffer scratch_;
  VkDeviceSize scratch_slice_ = 0;
};

}  // namespace scene
