#pragma once
// A frame's command pool (reset every frame, as engines recycle theirs), its one command buffer, recorded anew
// each frame, and the fence the frame is waited for with.
#include <vulkan/vulkan.h>

#include "vkkit.h"

namespace refit {

class FrameCommands {
 public:
  FrameCommands(vkkit::Device& device, VkPhysicalDevice gpu);
  ~FrameCommands();
  FrameCommands(const FrameCommands&) = delete;
  FrameCommands& operator=(const FrameCommands&) = delete;

  // Resets the pool and begins the command buffer (ONE_TIME_SUBMIT).
  VkCommandBuffer Begin();
  void End();
  // One vkQueueSubmit with the fence, then the wait for it.
  void SubmitAndWait();

 private:
  VkDevice device_;
  VkQueue queue_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cb_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

}  // namespace refit
