#pragma once
// GPU time of one frame's command buffer: a timestamp at its start and one at its end (vkCmdWriteTimestamp),
// read back after the frame's fence. Without timestamp support on the queue, available() is false and the
// benchmark prints no GPU time.
#include <vulkan/vulkan.h>

#include "vkkit.h"

namespace refit {

class GpuTimer {
 public:
  GpuTimer(vkkit::Device& device, VkPhysicalDevice gpu);
  ~GpuTimer();
  GpuTimer(const GpuTimer&) = delete;
  GpuTimer& operator=(const GpuTimer&) = delete;

  bool available() const { return pool_ != VK_NULL_HANDLE; }
  // Resets the two queries and writes the first: the command buffer's first commands.
  void RecordStart(VkCommandBuffer cb) const;
  // The second timestamp: the command buffer's last command.
  void RecordEnd(VkCommandBuffer cb) const;
  // Milliseconds between the two, once the command buffer completed.
  double ReadMilliseconds() const;

 private:
  VkDevice device_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  double nanoseconds_per_tick_ = 1.0;
  uint64_t valid_mask_ = ~uint64_t{0};
};

}  // namespace refit
