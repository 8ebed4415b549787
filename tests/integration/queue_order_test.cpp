// Execution order follows the semaphores (issue 25, item 8). A submission that waits for a timeline value nothing
// has signaled yet runs after whatever signals it: the layer applies and judges it then, not in host order.
//
// Lavapipe offers one queue. On one queue the device runs batches in submission order, so what one queue can show
// is the deferral itself: a batch that waits for a value the host signals later (valid: vkSignalSemaphore from the
// host) is judged when the host signals it, not when it is submitted; and in protect mode an error found then halts
// later submissions, because the batch went down already. Two queues with a wait-before-signal across them (the
// case that gave false positives) run where the device offers two queues (the NVIDIA H200) and skip on lavapipe;
// tests/unit/queue_order_unit_test.cpp runs the same over two fake queues everywhere.
#include <catch2/catch_test_macros.hpp>

#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* k03762 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03762";

TEST_CASE("order: an update waiting for a value the host signals later is judged when the host signals it (03762)",
          "[integration][history][order][passes-invalid-down]") {
  HistoryFixture f("history", {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  const VkCommandBuffer update = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kNoDuplicate); });
  // Waits for 1, which nothing has signaled: not judged yet (before the fix: 03762 here, at vkQueueSubmit).
  CHECK(SubmitOn(device.queue(), update, timeline, 1, 0) == VK_SUCCESS);
  CHECK(f.monitor().Take().empty());
  REQUIRE(timeline.HostSignal(1) == VK_SUCCESS);
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].id_name == k03762);
  CHECK(messages[0].text.find("vkQueueSubmit(): pSubmits[0].pCommandBuffers[0]") != std::string::npos);
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
}

TEST_CASE("order valid twin: a batch waiting for the host, and a later one on its queue, applied in queue order",
          "[integration][history][order]") {
  HistoryFixture f(nullptr, {}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  const VkCommandBuffer update = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kOpaque); });
  const VkCommandBuffer rebuild = Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kNoDuplicate); });
  REQUIRE(SubmitOn(device.queue(), update, timeline, 1, 2) == VK_SUCCESS);
  REQUIRE(SubmitOn(device.queue(), rebuild, timeline, 0, 0) == VK_SUCCESS);  // runs after the update: its queue
  REQUIRE(timeline.HostSignal(1) == VK_SUCCESS);
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
  // The rebuild ran last: an update repeating it is valid.
  CHECK(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kNoDuplicate); })) ==
        VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("order: protect mode halts later submissions after an error found when a deferred batch is judged",
          "[integration][history][order][protect][passes-invalid-down]") {
  HistoryFixture f("history", {{"protect", "true"}}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  const VkCommandBuffer update = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kNoDuplicate); });
  CHECK(SubmitOn(device.queue(), update, timeline, 1, 0) == VK_SUCCESS);  // went down before it could be judged
  f.monitor().Expect(k03762);
  REQUIRE(timeline.HostSignal(1) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
  // Whatever the invalid update left is not traced: every later submission is withheld.
  CHECK(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) ==
        VK_ERROR_VALIDATION_FAILED_EXT);
}

TEST_CASE("order valid twin: protect mode lets a valid deferred batch and what follows through",
          "[integration][history][order][protect]") {
  HistoryFixture f(nullptr, {{"protect", "true"}}, TimelineDevice());
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  const VkCommandBuffer update = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kOpaque); });
  CHECK(SubmitOn(device.queue(), update, timeline, 1, 0) == VK_SUCCESS);
  REQUIRE(timeline.HostSignal(1) == VK_SUCCESS);
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
  CHECK(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kOpaque); })) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

// Two queues: queue 0's update waits for a value queue 1 signals after its rebuild, submitted later. The device
// runs the rebuild first. Where the device has one queue (lavapipe) this skips: see the unit test.
TEST_CASE("order valid twin: an update waiting for another queue's later rebuild is judged against that rebuild",
          "[integration][history][order][two-queues]") {
  HistoryFixture f(nullptr, {}, TimelineDevice(2));
  vkkit::Device& device = f.device();
  if (device.queue_count() < 2) SKIP("the device offers one queue in its compute family");
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); })) == VK_SUCCESS);
  const VkCommandBuffer update = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kNoDuplicate); });
  const VkCommandBuffer rebuild = Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kNoDuplicate); });
  REQUIRE(SubmitOn(device.queue(0), update, timeline, 1, 0) == VK_SUCCESS);  // before the fix: 03762 here
  REQUIRE(SubmitOn(device.queue(1), rebuild, timeline, 0, 1) == VK_SUCCESS);
  vkkit::Check(vkQueueWaitIdle(device.queue(0)), "vkQueueWaitIdle");
  vkkit::Check(vkQueueWaitIdle(device.queue(1)), "vkQueueWaitIdle");
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("order: an update contradicting another queue's later rebuild that runs before it is reported (03762)",
          "[integration][history][order][two-queues][passes-invalid-down]") {
  HistoryFixture f("history", {}, TimelineDevice(2));
  vkkit::Device& device = f.device();
  if (device.queue_count() < 2) SKIP("the device offers one queue in its compute family");
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Timeline timeline(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kNoDuplicate); })) ==
          VK_SUCCESS);
  const VkCommandBuffer update = Recorded(commands, [&](VkCommandBuffer cb) { blas.Update(cb, kNoDuplicate); });
  const VkCommandBuffer rebuild = Recorded(commands, [&](VkCommandBuffer cb) { blas.Build(cb, kOpaque); });
  REQUIRE(SubmitOn(device.queue(0), update, timeline, 1, 0) == VK_SUCCESS);  // before the fix: silent
  CHECK(f.monitor().Take().empty());
  f.monitor().Expect(k03762);
  // Reported when the rebuild that runs before it is submitted; both went down (the rebuild is valid itself).
  CHECK(SubmitOn(device.queue(1), rebuild, timeline, 0, 1) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  vkkit::Check(vkQueueWaitIdle(device.queue(0)), "vkQueueWaitIdle");
  vkkit::Check(vkQueueWaitIdle(device.queue(1)), "vkQueueWaitIdle");
}

}  // namespace
}  // namespace asval_test
