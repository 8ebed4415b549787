// Family lifetime (issue 29): the engine patterns that destroy what acceleration-structure work used, validly
// (deferred deletion after a fence wait). The fault itself is the scene's scratch-destroyed-while-pending: a corpus
// case's callback skips the destroy a layer reports, and a layer that does not make it later (the Khronos layer)
// leaks the buffer, which LeakSanitizer reports in the sanitizer build's corpus run.
#include "corpus.h"
#include "history_helpers.h"

namespace corpus {
namespace {

using asval_test::Blas;
using asval_test::Commands;
using asval_test::Inputs;
using asval_test::Shape;
using asval_test::Tlas;

constexpr uint64_t kTenSeconds = 10ull * 1000 * 1000 * 1000;

VkFence MakeFence(vkkit::Device& device) {
  VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  vkkit::Check(vkCreateFence(device.handle(), &info, nullptr, &fence), "vkCreateFence");
  return fence;
}

void Submit(vkkit::Device& device, VkCommandBuffer cb, VkFence fence) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  vkkit::Check(vkQueueSubmit(device.queue(), 1, &submit, fence), "vkQueueSubmit");
}

}  // namespace

CORPUS_CASE(FramesInFlightDeferredDeletion, "lifetime-frames-in-flight-deferred-deletion", "patterns",
            "two frames in flight, each rebuilding the TLAS from its own new instance buffer; a frame's instance "
            "buffer is destroyed once its fence was waited for, while the next frame is still pending",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Tlas tlas(device, 4);
  Commands commands(device);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, Shape{}); });
  constexpr int kFrames = 6;
  std::vector<vkkit::Buffer> instances(kFrames);
  std::vector<VkFence> fences(kFrames);
  for (int frame = 0; frame < kFrames; ++frame) {
    instances[frame] = tlas.MakeInstances({&blas, &blas});
    fences[frame] = MakeFence(device);
    VkCommandBuffer cb = commands.Begin();
    tlas.Record(cb, instances[frame], 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    commands.End(cb);
    Submit(device, cb, fences[frame]);
    if (frame >= 1) {
      // Frame N-1 is waited for and its buffer destroyed while frame N may still run.
      vkkit::Check(vkWaitForFences(device.handle(), 1, &fences[frame - 1], VK_TRUE, kTenSeconds), "vkWaitForFences");
      device.Destroy(instances[frame - 1]);
    }
  }
  vkkit::Check(vkWaitForFences(device.handle(), 1, &fences[kFrames - 1], VK_TRUE, kTenSeconds), "vkWaitForFences");
  device.Destroy(instances[kFrames - 1]);
  for (VkFence fence : fences) vkDestroyFence(device.handle(), fence, nullptr);
}

CORPUS_CASE(BlasStreaming, "lifetime-blas-streaming-out-after-fence", "patterns",
            "BLASes streamed in and out while the TLAS is rebuilt every frame: a BLAS and its inputs are destroyed "
            "once the fence of the last frame whose TLAS referenced it was waited for",
            {}) {
  Tlas tlas(device, 4);
  Commands commands(device);
  std::vector<std::unique_ptr<Inputs>> inputs;
  std::vector<std::unique_ptr<Blas>> blases;
  VkFence previous = VK_NULL_HANDLE;
  for (int frame = 0; frame < 5; ++frame) {
    // Stream one in: built this frame, referenced by this frame's TLAS.
    inputs.push_back(std::make_unique<Inputs>(device));
    blases.push_back(std::make_unique<Blas>(device, *inputs.back()));
    vkkit::Buffer instances = tlas.MakeInstances({blases.back().get()});
    const VkFence fence = MakeFence(device);
    VkCommandBuffer cb = commands.Begin();
    blases.back()->Build(cb, Shape{});
    commands.Barrier(cb);
    tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    commands.End(cb);
    Submit(device, cb, fence);
    if (previous) {
      // Stream the previous one out: the frame that last referenced it completed.
      vkkit::Check(vkWaitForFences(device.handle(), 1, &previous, VK_TRUE, kTenSeconds), "vkWaitForFences");
      vkDestroyFence(device.handle(), previous, nullptr);
      blases[blases.size() - 2].reset();
      inputs[inputs.size() - 2].reset();
    }
    previous = fence;
    vkkit::Check(vkWaitForFences(device.handle(), 1, &fence, VK_TRUE, kTenSeconds), "vkWaitForFences");
    device.Destroy(instances);
  }
  vkDestroyFence(device.handle(), previous, nullptr);
}

}  // namespace corpus
