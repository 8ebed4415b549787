// Family lifetime (issue 29): structures, buffers and memory destroyed or freed while a submitted
// acceleration-structure command that uses them has not completed. The submission is held pending by a timeline
// wait the host signals after the destroy, so that the device cannot have finished it; the destroys the tests
// expect are skipped by the monitor's VK_TRUE, which the layer honours by making them once the work completed.
#include <catch2/catch_test_macros.hpp>
#include <memory>

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
  (void)inputs.release();  // destroyed above (the layer makes both calls once the build completed)
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
