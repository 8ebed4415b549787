#pragma once
// The deforming bottom-level structures: a flag (cloth with holes and growing confetti, plus its pole: two
// geometries in one structure) and a breathing blob. A compute shader writes their vertices on the device
// each frame, alternating between two output buffers (so each refit reads a new address, as engines do),
// and the structures, built once with ALLOW_UPDATE, are refit in place every frame.
#include <array>
#include <cstdint>

#include "build_input.h"
#include "gpu.h"
#include "meshes.h"

namespace scene {

class DeformingBlases {
 public:
  struct Params {  // shaders/deform.comp's Params
    float time;
    uint32_t revive_dead;
    uint32_t vertex_count;
    uint32_t unused;
  };

  static constexpr VkBuildAccelerationStructureFlagsKHR kFlags =
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;

  explicit DeformingBlases(Gpu& gpu);
  ~DeformingBlases();
  DeformingBlases(const DeformingBlases&) = delete;
  DeformingBlases& operator=(const DeformingBlases&) = delete;

  Params& params() { return *static_cast<Params*>(params_.mapped); }
  const DeformingMeshes& meshes() const { return meshes_; }
  uint32_t* cloth_indices() { return static_cast<uint32_t*>(indices_.mapped); }  // host-visible, read by builds

  // Build inputs reading the vertices written in frames of this parity.
  BuildInput FlagInput(uint32_t parity) const;
  BuildInput BlobInput(uint32_t parity) const;
  const AccelerationStructure& flag() const { return flag_; }
  const AccelerationStructure& blob() const { return blob_; }
  VkDeviceAddress flag_scratch() const { return scratch_.address; }
  VkDeviceAddress blob_scratch() const { return scratch_.address + blob_scratch_offset_; }
  // Structures and scratch are sized for these variants too, so that an injected fault breaks one rule only.
  static BuildInput WithCompactionFlag(BuildInput input);

  // The compute pass writing this parity's vertices, then a barrier before the builds that read them.
  void RecordAnimate(VkCommandBuffer cb, uint32_t parity) const;
  // Both structures in one vkCmdBuildAccelerationStructuresKHR (BUILD, or UPDATE in place), then a barrier.
  void RecordBuilds(VkCommandBuffer cb, uint32_t parity, VkBuildAccelerationStructureModeKHR mode) const;

 private:
  void CreatePipeline();

  Gpu& gpu_;
  DeformingMeshes meshes_;
  Buffer rest_;
  Buffer params_;
  Buffer indices_;  // cloth, pole, blob
  VkDeviceSize pole_indices_offset_ = 0;
  VkDeviceSize blob_indices_offset_ = 0;
  MemoryBlock output_block_;            // both output buffers live in one allocation
  std::array<Buffer, 2> positions_;     // vec4 per vertex, by frame parity
  AccelerationStructure flag_;
  AccelerationStructure blob_;
  Buffer scratch_;
  VkDeviceSize blob_scratch_offset_ = 0;

  PipelineObjects pipe_;
  std::array<VkDescriptorSet, 2> sets_{};
};

}  // namespace scene
