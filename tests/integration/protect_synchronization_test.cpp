// A submission protect mode withholds still completes the app's synchronization (issue 26): its batches go down
// without their command buffers (layer/loader/synchronization_only.h), so an app that ignores the
// VK_ERROR_VALIDATION_FAILED_EXT and then waits, on the host for the fence or a timeline value, in a later
// submission for a binary semaphore, or on another queue for a timeline value, is never left waiting; and nothing it
// recorded runs (a fill recorded before the withheld command leaves its buffer untouched). Every wait here is
// bounded (10 s): a failure is a failed check, not a hung test.
//
// The withheld submissions hold an update whose geometry flags differ from the build it updates (03762, judged at
// submission in execution order), or come after a halt (an error found when a deferred batch was judged). Lavapipe
// offers one queue; the case with a second queue waiting runs where the device offers two (the NVIDIA H200) and
// skips on lavapipe.
#include <catch2/catch_test_macros.hpp>

#include <cstring>

#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* k03762 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03762";
constexpr uint64_t kTenSeconds = 10'000'000'000ull;
constexpr uint32_t kFill = 0xabababab;

// A host-visible buffer of zeros that a recorded vkCmdFillBuffer marks: whether that command ran.
class Marker {
 public:
  explicit Marker(vkkit::Device& device) : device_(device) {
    buffer_ = device.CreateBuffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    std::memset(buffer_.mapped, 0, 256);
  }
  ~Marker() { device_.Destroy(buffer_); }
  Marker(const Marker&) = delete;
  Marker& operator=(const Marker&) = delete;
  void Fill(VkCommandBuffer cb) const { vkCmdFillBuffer(cb, buffer_.buffer, 0, 256, kFill); }
  bool Filled() const {
    uint32_t word = 0;
    std::memcpy(&word, buffer_.mapped, sizeof(word));
    return word == kFill;
  }

 private:
  vkkit::Device& device_;
  vkkit::Buffer buffer_;
};

class Fence {
 public:
  explicit Fence(vkkit::Device& device) : device_(device) {
    const VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    vkkit::Check(vkCreateFence(device.handle(), &info, nullptr, &fence_), "vkCreateFence");
  }
  ~Fence() { vkDestroyFence(device_.handle(), fence_, nullptr); }
  Fence(const Fence&) = delete;
  Fence& operator=(const Fence&) = delete;
  VkFence handle() const { return fence_; }
  VkResult Wait() const { return vkWaitForFences(device_.handle(), 1, &fence_, VK_TRUE, kTenSeconds); }

 private:
  vkkit::Device& device_;
  VkFence fence_ = VK_NULL_HANDLE;
};

class BinarySemaphore {
 public:
  explicit BinarySemaphore(vkkit::Device& device) : device_(device) {
    const VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    vkkit::Check(vkCreateSemaphore(device.handle(), &info, nullptr, &semaphore_), "vkCreateSemaphore");
  }
  ~BinarySemaphore() { vkDestroySemaphore(device_.handle(), semaphore_, nullptr); }
  BinarySemaphore(const BinarySemaphore&) = delete;
  BinarySemaphore& operator=(const BinarySemaphore&) = delete;
  VkSemaphore handle() const { return semaphore_; }

 private:
  vkkit::Device& device_;
  VkSemaphore semaphore_ = VK_NULL_HANDLE;
};

// One batch of `cb` on `queue`: it signals `binary` (if any) and `timeline` to `value`, with `fence`.
VkResult SubmitSignaling(VkQueue queue, VkCommandBuffer cb, const BinarySemaphore* binary, const Timeline& timeline,
                         uint64_t value, const Fence& fence) {
  const VkSemaphore signals[2] = {timeline.handle(), binary ? binary->handle() : VK_NULL_HANDLE};
  const uint64_t values[2] = {value, 0};
  VkTimelineSemaphoreSubmitInfo timeline_values{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  timeline_values.signalSemaphoreValueCount = binary ? 2 : 1;
  timeline_values.pSignalSemaphoreValues = values;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, &timeline_values};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  submit.signalSemaphoreCount = binary ? 2 : 1;
  submit.pSignalSemaphores = signals;
  return vkQueueSubmit(queue, 1, &submit, fence.handle());
}

// One batch of `cb` on `queue` that waits for `binary`, with `fence`.
VkResult SubmitWaiting(VkQueue queue, VkCommandBuffer cb, const BinarySemaphore& binary, const Fence& fence) {
  const VkSemaphore wait = binary.handle();
  const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &wait;
  submit.pWaitDstStageMask = &stage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cb;
  return vkQueueSubmit(queue, 1, &submit, fence.handle());
}

TEST_CASE("protect: a withheld submission still signals its fence, its binary semaphore for the next submission and "
          "its timeline value; nothing it recorded runs",
          "[integration][protect][synchronization]") {
  HistoryFixture f("history", {{"protect", "true"}}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  BinarySemaphore binary(device);
  Fence withheld_fence(device), next_fence(device);
  Marker withheld_marker(device), next_marker(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);

  const VkCommandBuffer invalid = Recorded(commands, [&](VkCommandBuffer cb) {
    withheld_marker.Fill(cb);
    blas.Update(cb, kNoDuplicate);  // its geometry flags differ from the build's: 03762 at submission
  });
  f.monitor().Expect(k03762);
  CHECK(SubmitSignaling(device.queue(), invalid, &binary, timeline, 1, withheld_fence) ==
        VK_ERROR_VALIDATION_FAILED_EXT);
  // The app ignores the result and goes on: a submission waiting for the withheld one's binary semaphore...
  const VkCommandBuffer next = Recorded(commands, [&](VkCommandBuffer cb) { next_marker.Fill(cb); });
  CHECK(SubmitWaiting(device.queue(), next, binary, next_fence) == VK_SUCCESS);
  // ...then waits on the host for everything the withheld submission would have signaled.
  CHECK(withheld_fence.Wait() == VK_SUCCESS);
  CHECK(timeline.HostWait(1, kTenSeconds) == VK_SUCCESS);
  CHECK(next_fence.Wait() == VK_SUCCESS);
  vkkit::Check(vkDeviceWaitIdle(device.handle()), "vkDeviceWaitIdle");
  CHECK_FALSE(withheld_marker.Filled());  // nothing of the withheld command buffer ran
  CHECK(next_marker.Filled());
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("protect valid twin: the same submissions, valid, run and signal as they did",
          "[integration][protect][synchronization]") {
  HistoryFixture f("history", {{"protect", "true"}}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  BinarySemaphore binary(device);
  Fence first_fence(device), next_fence(device);
  Marker first_marker(device), next_marker(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  const VkCommandBuffer valid = Recorded(commands, [&](VkCommandBuffer cb) {
    first_marker.Fill(cb);
    blas.Update(cb, kOpaque);
  });
  CHECK(SubmitSignaling(device.queue(), valid, &binary, timeline, 1, first_fence) == VK_SUCCESS);
  const VkCommandBuffer next = Recorded(commands, [&](VkCommandBuffer cb) { next_marker.Fill(cb); });
  CHECK(SubmitWaiting(device.queue(), next, binary, next_fence) == VK_SUCCESS);
  CHECK(first_fence.Wait() == VK_SUCCESS);
  CHECK(timeline.HostWait(1, kTenSeconds) == VK_SUCCESS);
  CHECK(next_fence.Wait() == VK_SUCCESS);
  CHECK(first_marker.Filled());
  CHECK(next_marker.Filled());
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("protect: after a halt, each withheld submission still signals its fence and timeline value",
          "[integration][protect][synchronization][passes-invalid-down]") {
  HistoryFixture f("history", {{"protect", "true"}}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  Fence fence(device);
  Marker marker(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  // An update waiting for a value the host signals later went down before it could be judged (harmless to the
  // driver: geometry flags); judged at the signal, its error halts every later submission.
  const VkCommandBuffer update = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kNoDuplicate); });
  REQUIRE(SubmitOn(device.queue(), update, timeline, 1, 0) == VK_SUCCESS);
  f.monitor().Expect(k03762);
  REQUIRE(timeline.HostSignal(1) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  // A valid submission, withheld by the halt: its fence and its timeline value 2 still come.
  const VkCommandBuffer later = Recorded(commands, [&](VkCommandBuffer cb) { marker.Fill(cb); });
  CHECK(SubmitSignaling(device.queue(), later, nullptr, timeline, 2, fence) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(fence.Wait() == VK_SUCCESS);
  CHECK(timeline.HostWait(2, kTenSeconds) == VK_SUCCESS);
  vkkit::Check(vkDeviceWaitIdle(device.handle()), "vkDeviceWaitIdle");
  CHECK_FALSE(marker.Filled());
  CHECK(f.monitor().Verify() == "");
}

// Queue 1 waits for a timeline value that only queue 0's withheld submission signals: without its emptied batch,
// queue 1 (and vkDeviceWaitIdle) would wait for ever.
TEST_CASE("protect: another queue waiting for a withheld submission's timeline value runs",
          "[integration][protect][synchronization][two-queues]") {
  HistoryFixture f("history", {{"protect", "true"}}, TimelineDevice(2));
  vkkit::Device& device = f.device();
  if (device.queue_count() < 2) SKIP("the device offers one queue in its compute family");
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  Fence withheld_fence(device), waiting_fence(device);
  Marker withheld_marker(device), waiting_marker(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  // Submitted first, on queue 1: waits for value 1 (the layer defers it; the device waits).
  const VkCommandBuffer waiting = Recorded(commands, [&](VkCommandBuffer cb) { waiting_marker.Fill(cb); });
  {
    const VkSemaphore semaphore = timeline.handle();
    const uint64_t value = 1;
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkTimelineSemaphoreSubmitInfo values{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    values.waitSemaphoreValueCount = 1;
    values.pWaitSemaphoreValues = &value;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, &values};
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &semaphore;
    submit.pWaitDstStageMask = &stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &waiting;
    REQUIRE(vkQueueSubmit(device.queue(1), 1, &submit, waiting_fence.handle()) == VK_SUCCESS);
  }
  const VkCommandBuffer invalid = Recorded(commands, [&](VkCommandBuffer cb) {
    withheld_marker.Fill(cb);
    blas.Update(cb, kNoDuplicate);
  });
  f.monitor().Expect(k03762);
  CHECK(SubmitSignaling(device.queue(0), invalid, nullptr, timeline, 1, withheld_fence) ==
        VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(withheld_fence.Wait() == VK_SUCCESS);
  CHECK(waiting_fence.Wait() == VK_SUCCESS);
  vkkit::Check(vkDeviceWaitIdle(device.handle()), "vkDeviceWaitIdle");
  CHECK_FALSE(withheld_marker.Filled());
  CHECK(waiting_marker.Filled());
  CHECK(f.monitor().Verify() == "");
}

// Run only by tests/gate/withheld_waits_test.py, under scripts/asval-run (protect on from its environment): an app
// that ignores the withheld submission's error and waits without a timeout for its fence, for its binary semaphore
// through a next submission, for its timeline value on the host, then for the device to go idle. Before issue 26 it
// never returned; the gate must end it with exit 65 within the test's time.
TEST_CASE("protect child: waits without a timeout on a withheld submission", "[.][withheld-waits-child]") {
  HistoryFixture f(nullptr, {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  BinarySemaphore binary(device);
  Fence withheld_fence(device), next_fence(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  const VkCommandBuffer invalid = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kNoDuplicate); });
  (void)SubmitSignaling(device.queue(), invalid, &binary, timeline, 1, withheld_fence);  // the result is ignored
  const VkCommandBuffer next = Recorded(commands, [&](VkCommandBuffer) {});
  (void)SubmitWaiting(device.queue(), next, binary, next_fence);
  const VkFence fences[2] = {withheld_fence.handle(), next_fence.handle()};
  vkkit::Check(vkWaitForFences(device.handle(), 2, fences, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  vkkit::Check(timeline.HostWait(1, UINT64_MAX), "vkWaitSemaphores");
  vkkit::Check(vkDeviceWaitIdle(device.handle()), "vkDeviceWaitIdle");
}

}  // namespace
}  // namespace asval_test
