// Family lifetime (issue 29): structures, buffers and memory destroyed or freed while a submitted
// acceleration-structure command that uses them has not completed. The submission is held pending by a timeline
// wait the host signals after the destroy, so that the device cannot have finished it; the destroys the tests
// expect are skipped by the monitor's VK_TRUE, which the layer honours by making them once the work completed.
#include <catch2/catch_test_macros.hpp>
#include <chrono>
#include <memory>
#include <thread>

#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char kStructureInUse[] = "VUID-vkDestroyAccelerationStructureKHR-accelerationStructure-02442";
constexpr const char kBufferInUse[] = "VUID-vkDestroyBuffer-buffer-00922";
constexpr const char kMemoryInUse[] = "VUID-vkFreeMemory-memory-00677";
constexpr uint64_t kTenSeconds = 10ull * 1000 * 1000 * 1000;

TEST_CASE(
    "lifetime: a build's input buffer destroyed and its memory freed before the submission completed are "
    "reported (buffer-00922, memory-00677)",
    "[integration][lifetime]") {
  HistoryFixture f("lifetime", {}, TimelineDevice());
  vkkit::Device& device = f.device();
  auto inputs = std::make_unique<Inputs>(device);
  Blas blas(device, *inputs);
  Commands commands(device);
  Timeline gate(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
  REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);  // runs once the host signals 1
  const vkkit::Buffer held = inputs->buffer();
  f.monitor().Expect(kBufferInUse);
  vkDestroyBuffer(device.handle(), held.buffer, nullptr);
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect(kMemoryInUse);
  vkFreeMemory(device.handle(), held.memory, nullptr);
  CHECK(f.monitor().Verify() == "");
  inputs->Forget();  // destroyed above (the layer makes both calls once the build completed)
  CHECK(gate.HostSignal(1) == VK_SUCCESS);
  CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "lifetime: a structure destroyed before the submission building it completed is reported "
    "(accelerationStructure-02442)",
    "[integration][lifetime]") {
  HistoryFixture f("lifetime", {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline gate(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
  REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);
  f.monitor().Expect(kStructureInUse);
  blas.DestroyHandle();
  CHECK(f.monitor().Verify() == "");
  CHECK(gate.HostSignal(1) == VK_SUCCESS);
  CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "lifetime valid twin: inputs, memory and structures destroyed after the work completed, or while other "
    "work is pending, stay silent",
    "[integration][lifetime]") {
  HistoryFixture f(nullptr, {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  Timeline gate(device);
  // Completed, learned by a timeline wait on the host (no fence, no queue wait): destroyed at once.
  {
    auto inputs = std::make_unique<Inputs>(device);
    Blas blas(device, *inputs);
    const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
    REQUIRE(SubmitOn(device.queue(), cb, gate, 0, 1) == VK_SUCCESS);
    REQUIRE(gate.HostWait(1, kTenSeconds) == VK_SUCCESS);
    inputs.reset();
    blas.DestroyHandle();
    CHECK(f.monitor().Verify() == "");
  }
  // Deferred deletion: the previous frame's inputs and structure go while this frame's build (other buffers, another
  // structure) is still held pending.
  {
    auto old_inputs = std::make_unique<Inputs>(device);
    auto old_blas = std::make_unique<Blas>(device, *old_inputs);
    REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { old_blas->Build(c, Shape{}); })) ==
            VK_SUCCESS);  // waits for the queue
    Inputs inputs(device);
    Blas blas(device, inputs);
    const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
    REQUIRE(SubmitOn(device.queue(), cb, gate, 2, 3) == VK_SUCCESS);
    old_blas.reset();
    old_inputs.reset();
    CHECK(f.monitor().Verify() == "");
    CHECK(gate.HostSignal(2) == VK_SUCCESS);
    CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  }
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test

namespace asval_test {
namespace {

VkFence MakeFence(vkkit::Device& device) {
  VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  REQUIRE(vkCreateFence(device.handle(), &info, nullptr, &fence) == VK_SUCCESS);
  return fence;
}

VkResult SubmitWithFence(VkQueue queue, VkCommandBuffer cb, VkFence fence) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  return vkQueueSubmit(queue, 1, &submit, fence);
}

TEST_CASE(
    "lifetime: the buffer a structure was created on, destroyed before the submission building the structure "
    "completed, is reported (buffer-00922)",
    "[integration][lifetime]") {
  HistoryFixture f("lifetime", {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline gate(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
  REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);
  f.monitor().Expect(kBufferInUse);
  blas.DestroyStorageBuffer();
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("the storage of VkAccelerationStructureKHR") != std::string::npos);
  CHECK(gate.HostSignal(1) == VK_SUCCESS);
  CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "lifetime valid twin: frames in flight with the app's fences, each frame's inputs destroyed once its fence "
    "was waited for while the next frame is pending, stay silent",
    "[integration][lifetime]") {
  HistoryFixture f(nullptr, {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  Timeline gate(device);
  Inputs base(device);
  Blas blas(device, base);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, Shape{}); });
  constexpr int kFrames = 4;
  std::vector<std::unique_ptr<Inputs>> inputs;
  std::vector<VkFence> fences;
  for (int frame = 0; frame < kFrames; ++frame) {
    inputs.push_back(std::make_unique<Inputs>(device));  // this frame's vertices
    fences.push_back(MakeFence(device));
    blas.SetInputs(*inputs.back());
    const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Update(c, Shape{}); });
    if (frame + 1 < kFrames) {
      REQUIRE(SubmitWithFence(device.queue(), cb, fences.back()) == VK_SUCCESS);
    } else {
      // The last frame is held pending (a timeline wait) while the earlier frames' inputs go.
      REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);
    }
    if (frame >= 1 && frame + 1 < kFrames) {
      // Deferred deletion: the frame before this one, once its fence was waited for.
      REQUIRE(vkWaitForFences(device.handle(), 1, &fences[frame - 1], VK_TRUE, kTenSeconds) == VK_SUCCESS);
      inputs[frame - 1].reset();
    }
  }
  REQUIRE(vkWaitForFences(device.handle(), 1, &fences[kFrames - 2], VK_TRUE, kTenSeconds) == VK_SUCCESS);
  inputs[kFrames - 2].reset();
  CHECK(f.monitor().Verify() == "");
  CHECK(gate.HostSignal(1) == VK_SUCCESS);
  CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  for (VkFence fence : fences) vkDestroyFence(device.handle(), fence, nullptr);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "lifetime valid twin: an alias of the input buffer over the same memory destroyed while the build is "
    "pending stays silent (the build's buffer still holds the address)",
    "[integration][lifetime][khronos-whole-submission]") {
  HistoryFixture f(nullptr, {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline gate(device);
  // A second buffer over the inputs' memory (a view a sub-allocator keeps): lavapipe gives it the same address.
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = inputs.buffer().size;
  info.usage =
      VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
  VkBuffer alias = VK_NULL_HANDLE;
  REQUIRE(vkCreateBuffer(device.handle(), &info, nullptr, &alias) == VK_SUCCESS);
  REQUIRE(vkBindBufferMemory(device.handle(), alias, inputs.buffer().memory, 0) == VK_SUCCESS);
  const VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO, nullptr, alias};
  REQUIRE(vkGetBufferDeviceAddress(device.handle(), &address) == inputs.buffer().address);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
  REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);
  vkDestroyBuffer(device.handle(), alias, nullptr);
  CHECK(f.monitor().Verify() == "");
  CHECK(gate.HostSignal(1) == VK_SUCCESS);
  CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "lifetime valid twin: inputs destroyed once the host saw an event the device set after the build, while "
    "the rest of the submission is pending, stay silent",
    "[integration][lifetime][khronos-whole-submission]") {
  HistoryFixture f(nullptr, {}, TimelineDevice());
  vkkit::Device& device = f.device();
  auto inputs = std::make_unique<Inputs>(device);
  Blas blas(device, *inputs);
  Commands commands(device);
  VkEventCreateInfo event_info{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
  VkEvent built = VK_NULL_HANDLE, go_on = VK_NULL_HANDLE;
  REQUIRE(vkCreateEvent(device.handle(), &event_info, nullptr, &built) == VK_SUCCESS);
  REQUIRE(vkCreateEvent(device.handle(), &event_info, nullptr, &go_on) == VK_SUCCESS);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) {
    blas.Build(c, Shape{});
    vkCmdSetEvent(c, built, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
    // The rest of the submission waits for the host.
    vkCmdWaitEvents(c, 1, &go_on, VK_PIPELINE_STAGE_HOST_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, nullptr, 0, nullptr, 0,
                    nullptr);
  });
  const VkFence fence = MakeFence(device);
  REQUIRE(SubmitWithFence(device.queue(), cb, fence) == VK_SUCCESS);
  VkResult status = VK_EVENT_RESET;
  for (int tries = 0; tries < 10000 && status != VK_EVENT_SET; ++tries) {
    status = vkGetEventStatus(device.handle(), built);
    if (status != VK_EVENT_SET) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  REQUIRE(status == VK_EVENT_SET);
  inputs.reset();  // the build ran: its inputs may go, though the submission's fence has not signaled
  CHECK(f.monitor().Verify() == "");
  REQUIRE(vkSetEvent(device.handle(), go_on) == VK_SUCCESS);
  REQUIRE(vkWaitForFences(device.handle(), 1, &fence, VK_TRUE, kTenSeconds) == VK_SUCCESS);
  vkDestroyFence(device.handle(), fence, nullptr);
  vkDestroyEvent(device.handle(), built, nullptr);
  vkDestroyEvent(device.handle(), go_on, nullptr);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
