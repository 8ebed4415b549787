#include "frame_commands.h"

#include <cstdint>

#include "queue_family.h"

namespace refit {

using vkkit::Check;

FrameCommands::FrameCommands(vkkit::Device& device, VkPhysicalDevice gpu)
    : device_(device.handle()), queue_(device.queue()) {
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool_info.queueFamilyIndex = DeviceQueueFamily(gpu);
  Check(vkCreateCommandPool(device_, &pool_info, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  Check(vkAllocateCommandBuffers(device_, &alloc, &cb_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  Check(vkCreateFence(device_, &fence_info, nullptr, &fence_), "vkCreateFence");
}

FrameCommands::~FrameCommands() {
  vkDestroyFence(device_, fence_, nullptr);
  vkDestroyCommandPool(device_, pool_, nullptr);
}

VkCommandBuffer FrameCommands::Begin() {
  Check(vkResetCommandPool(device_, pool_, 0), "vkResetCommandPool");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  Check(vkBeginCommandBuffer(cb_, &begin), "vkBeginCommandBuffer");
  return cb_;
}

void FrameCommands::End() { Check(vkEndCommandBuffer(cb_), "vkEndCommandBuffer"); }

void FrameCommands::SubmitAndWait() {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb_;
  Check(vkQueueSubmit(queue_, 1, &submit, fence_), "vkQueueSubmit");
  Check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  Check(vkResetFences(device_, 1, &fence_), "vkResetFences");
}

}  // namespace refit
