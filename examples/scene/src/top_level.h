#pragma once
// The top-level structure: the ground plus `count - 1` instances of the bottom-level structures on a grid,
// spinning over time. Instance data is written on the host every frame into one of two buffers that share a
// memory block (so the update reads a new address each frame); the structure is built with ALLOW_UPDATE,
// updated in place, and rebuilt from time to time. Some instances are inactive (reference 0) in every frame;
// a few have mask 0, which is still an active instance.
#include <array>
#include <cstdint>
#include <vector>

#include "build_input.h"
#include "gpu.h"

namespace scene {

// A bottom-level structure the instances can use.
struct Prototype {
  VkDeviceAddress address;  // of the structure
  uint32_t hit_group;       // 0: triangles, 1: procedural spheres
  float scale;
  uint32_t weight;          // how often it appears, relative to the others
};

class TopLevel {
 public:
  static constexpr VkBuildAccelerationStructureFlagsKHR kFlags =
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;

  TopLevel(Gpu& gpu, uint32_t count, const Prototype& ground, const std::vector<Prototype>& prototypes);
  ~TopLevel();
  TopLevel(const TopLevel&) = delete;
  TopLevel& operator=(const TopLevel&) = delete;

  const AccelerationStructure& structure() const { return tlas_; }
  uint32_t count() const { return static_cast<uint32_t>(placements_.size()); }
  uint32_t inactive() const { return inactive_; }
  VkAccelerationStructureInstanceKHR* instances(uint32_t parity) {
    return static_cast<VkAccelerationStructureInstanceKHR*>(instances_[parity].mapped);
  }

  void WriteInstances(uint32_t parity, float time);
  BuildInput Input(uint32_t parity) const;
  // Build or update in place from this parity's instances, then a barrier before ray tracing.
  void RecordBuild(VkCommandBuffer cb, uint32_t parity, VkBuildAccelerationStructureModeKHR mode) const;
  VkDeviceAddress scratch() const { return scratch_.address; }

 private:
  struct Placement {
    uint32_t prototype;  // index into prototypes_
    float x, z, scale, angle, spin;
    uint32_t material;
    bool inactive;
    bool masked;  // mask 0: active, but no ray sees it
  };

  Gpu& gpu_;
  std::vector<Prototype> prototypes_;  // [0] is the ground
  std::vector<Placement> placements_;
  uint32_t inactive_ = 0;
  MemoryBlock instance_block_;
  std::array<Buffer, 2> instances_;
  AccelerationStructure tlas_;
  Buffer scratch_;
};

}  // namespace scene
