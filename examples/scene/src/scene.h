#pragma once
// The scene: its parts, the command buffers it reuses every frame, and the frame loop. A frame is one
// submission of three command buffers: animate + refit the deforming structures, and the --refits crowd (or, in
// frame 0, build them),
// update (every 4th frame: rebuild) the top-level structure, trace. With --static, frames after frame 0 only
// trace.
//
// The reusable command buffers are recorded before the one that first builds the deforming structures,
// which they update: recording order is not execution order, and a validator must follow the latter.
#include <array>
#include <cstdint>
#include <functional>
#include <string>

#include "crowd_blases.h"
#include "deforming_blases.h"
#include "findings.h"
#include "gpu.h"
#include "options.h"
#include "ray_tracer.h"
#include "static_blases.h"
#include "top_level.h"

namespace scene {

class Scene {
 public:
  Scene(Gpu& gpu, Findings& findings, const SceneOptions& options);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  void RunFrames();
  // Called after each frame with the number of frames done (the long-run checkpoints, frame_checkpoints.h);
  // empty: nothing is called.
  std::function<void(uint32_t frames_done)> after_frame;
  void WriteImage(const std::string& path) const;

  static float TimeOf(uint32_t frame) { return 0.1f * static_cast<float>(frame); }
  uint32_t frames_done() const { return frames_done_; }
  // The reusable animate + refit command buffer of frames of this parity.
  VkCommandBuffer refit_commands(uint32_t parity) const { return refit_[parity]; }

  // The parts, used by the fault injection too.
  Gpu& gpu;
  Findings& findings;
  const SceneOptions options;
  StaticBlases statics;
  DeformingBlases deforming;
  TopLevel top;
  RayTracer tracer;
  CrowdBlases crowd;  // --refits N: N more structures refit per frame, one call each (none by default)

 private:
  void RecordCommandBuffers();
  VkCommandBuffer Record(VkCommandBufferUsageFlags flags, const std::function<void(VkCommandBuffer)>& record);
  void Frame(uint32_t frame);

  VkCommandBuffer first_ = VK_NULL_HANDLE;  // frame 0: animate, then build the deforming structures
  std::array<VkCommandBuffer, 2> refit_{};
  std::array<VkCommandBuffer, 2> tlas_update_{};
  std::array<VkCommandBuffer, 2> tlas_build_{};
  VkCommandBuffer trace_ = VK_NULL_HANDLE;
  uint32_t frames_done_ = 0;
};

}  // namespace scene
