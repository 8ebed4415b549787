#pragma once
// The static bottom-level structures, built the way engines build them at load time: all in one
// vkCmdBuildAccelerationStructuresKHR with ALLOW_COMPACTION and one shared scratch buffer cut into
// 128-byte-aligned slices; the compacted sizes written by vkCmdWriteAccelerationStructuresPropertiesKHR
// right after, in the same command buffer; then compacted copies, and the originals destroyed at once.
#include <array>

#include "build_input.h"
#include "gpu.h"

namespace scene {

class StaticBlases {
 public:
  enum Kind { kGround, kRock, kTorus, kCrates, kSpheres, kCount };
  static const char* Name(Kind kind);

  explicit StaticBlases(Gpu& gpu);
  ~StaticBlases();
  StaticBlases(const StaticBlases&) = delete;
  StaticBlases& operator=(const StaticBlases&) = delete;

  const AccelerationStructure& structure(Kind kind) const { return compacted_[kind]; }
  const BuildInput& input(Kind kind) const { return inputs_[kind]; }
  VkDeviceSize built_bytes() const { return built_bytes_; }
  VkDeviceSize compacted_bytes() const { return compacted_bytes_; }

 private:
  void Upload();
  void BuildAndCompact();

  Gpu& gpu_;
  Buffer geometry_;  // every static input in one host-visible buffer, at aligned offsets
  std::array<BuildInput, kCount> inputs_;
  std::array<AccelerationStructure, kCount> compacted_;
  VkDeviceSize built_bytes_ = 0;
  VkDeviceSize compacted_bytes_ = 0;
};

}  // namespace scene
