#include "capture_helpers.h"

#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace asval_test {

void InputsWritten(VkCommandBuffer cb) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1,
                       &barrier, 0, nullptr, 0, nullptr);
}

VkCommandBuffer RecordWith(Commands& commands, const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBuffer cb = commands.Begin();
  record(cb);
  commands.End(cb);
  return cb;
}

void SubmitAndWait(vkkit::Device& device, VkCommandBuffer cb, Wait wait) {
  VkFence fence = VK_NULL_HANDLE;
  if (wait == Wait::kFence || wait == Wait::kFenceStatus) {
    VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    vkkit::Check(vkCreateFence(device.handle(), &info, nullptr, &fence), "vkCreateFence");
  }
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  vkkit::Check(vkQueueSubmit(device.queue(), 1, &submit, fence), "vkQueueSubmit");
  switch (wait) {
    case Wait::kQueueIdle: vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle"); break;
    case Wait::kFence:
      vkkit::Check(vkWaitForFences(device.handle(), 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
      break;
    case Wait::kFenceStatus:
      while (vkGetFenceStatus(device.handle(), fence) == VK_NOT_READY) std::this_thread::yield();
      break;
    case Wait::kDeviceIdle: vkkit::Check(vkDeviceWaitIdle(device.handle()), "vkDeviceWaitIdle"); break;
  }
  if (fence) vkDestroyFence(device.handle(), fence, nullptr);
}

std::string OnlyFinding(Monitor& monitor, const char* vuid, const std::string& text) {
  const std::vector<Message> messages = monitor.Take();
  if (messages.size() == 1 && messages[0].id_name == vuid && messages[0].text.find(text) != std::string::npos) {
    return "";
  }
  std::string seen = "expected one " + std::string(vuid) + " naming '" + text + "', got " +
                     std::to_string(messages.size()) + " message(s):\n";
  for (const Message& m : messages) seen += m.id_name + ": " + m.text + "\n";
  return seen;
}

bool CaptureReducedRun() {
  const char* method = std::getenv("VK_ASVAL_AS_VALIDATION_CAPTURE_METHOD");
  return method && std::string(method) == "reduce";
}

}  // namespace asval_test
