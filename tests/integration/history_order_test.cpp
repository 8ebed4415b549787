// Build history follows execution order, not recording order: command buffers recorded in one order and
// submitted in another, two builds of one structure with different geometry counts, resubmission, secondary
// command buffers. Negative tests record an invalid update (that recording reaches the driver, hence
// [passes-invalid-down]); the monitor's VK_TRUE keeps the submission itself away from lavapipe.
#include <catch2/catch_test_macros.hpp>

#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* k03667 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667";
constexpr const char* k03758 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";

Shape Geometries(uint32_t n) {
  Shape s;
  s.geometries = n;
  return s;
}

TEST_CASE("history: an update submitted before the build it was recorded after is reported (03667)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Shape{});
  commands.End(build);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Shape{});
  commands.End(update);
  f.monitor().Expect(k03667);
  CHECK(commands.Submit(update) == VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  // Named at submission, with where the update was recorded.
  CHECK(messages[0].text.find("vkQueueSubmit(): pSubmits[0].pCommandBuffers[0]") != std::string::npos);
  CHECK(messages[0].text.find("pInfos[0] of the 1st vkCmdBuildAccelerationStructuresKHR in VkCommandBuffer") !=
        std::string::npos);
  // The skipped submission changed nothing: the build, then the update, is valid.
  CHECK(commands.Submit(build) == VK_SUCCESS);
  CHECK(commands.Submit(update) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history valid twin: an update recorded before its build and submitted after it stays silent",
          "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer update = commands.Begin();  // recorded first
  blas.Update(update, Shape{});
  commands.End(update);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Shape{});
  commands.End(build);
  CHECK(commands.Submit(build) == VK_SUCCESS);
  CHECK(commands.Submit(update) == VK_SUCCESS);
  // Both in one submission, in execution order.
  CHECK(commands.Submit({build, update}) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: an update must match the build executed last, not the one recorded last (03758)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer one = commands.Begin();
  blas.Build(one, Geometries(1));
  commands.End(one);
  VkCommandBuffer two = commands.Begin();
  blas.Build(two, Geometries(2));
  commands.End(two);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Geometries(2));  // matches `two`, the build recorded last
  commands.End(update);
  CHECK(commands.Submit(two) == VK_SUCCESS);
  CHECK(commands.Submit(one) == VK_SUCCESS);  // executed last
  f.monitor().Expect(k03758);
  CHECK(commands.Submit(update) == VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("geometryCount is 2") != std::string::npos);
  CHECK(messages[0].text.find("with geometryCount 1") != std::string::npos);
}

TEST_CASE("history valid twin: the update matching the build executed last stays silent", "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer one = commands.Begin();
  blas.Build(one, Geometries(1));
  commands.End(one);
  VkCommandBuffer two = commands.Begin();
  blas.Build(two, Geometries(2));
  commands.End(two);
  VkCommandBuffer update_one = commands.Begin();
  blas.Update(update_one, Geometries(1));
  commands.End(update_one);
  CHECK(commands.Submit(two) == VK_SUCCESS);
  CHECK(commands.Submit(one) == VK_SUCCESS);
  CHECK(commands.Submit(update_one) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: a resubmitted command buffer applies again, against the history at that time",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer one = commands.Begin();
  blas.Build(one, Geometries(1));
  commands.End(one);
  VkCommandBuffer two = commands.Begin();
  blas.Build(two, Geometries(2));
  commands.End(two);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Geometries(2));
  commands.End(update);
  CHECK(commands.Submit(two) == VK_SUCCESS);
  CHECK(commands.Submit(update) == VK_SUCCESS);
  CHECK(commands.Submit(update) == VK_SUCCESS);  // resubmitted: still valid
  CHECK(f.monitor().Verify() == "");
  CHECK(commands.Submit(one) == VK_SUCCESS);
  f.monitor().Expect(k03758);
  CHECK(commands.Submit(update) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
  CHECK(commands.Submit(two) == VK_SUCCESS);  // resubmitting the 2-geometry build makes the update valid again
  CHECK(commands.Submit(update) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: a re-recorded or reset command buffer forgets what it held before", "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer two = commands.Begin();
  blas.Build(two, Geometries(2));
  commands.End(two);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Geometries(2));
  commands.End(update);
  VkCommandBuffer cb = commands.Begin();
  blas.Build(cb, Geometries(1));
  commands.End(cb);
  CHECK(commands.Submit(cb) == VK_SUCCESS);
  const VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  SECTION("re-recorded empty by vkBeginCommandBuffer") {
    REQUIRE(vkBeginCommandBuffer(cb, &begin) == VK_SUCCESS);
  }
  SECTION("reset by vkResetCommandBuffer, then recorded empty") {
    REQUIRE(vkResetCommandBuffer(cb, 0) == VK_SUCCESS);
    REQUIRE(vkBeginCommandBuffer(cb, &begin) == VK_SUCCESS);
  }
  commands.End(cb);
  // If the 1-geometry build were still in cb's log, submitting cb would make it the last build again.
  CHECK(commands.Submit(two) == VK_SUCCESS);
  CHECK(commands.Submit(cb) == VK_SUCCESS);
  CHECK(commands.Submit(update) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: a build in a secondary command buffer counts when the primary executing it is submitted",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Procs procs(device);
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Shape fixed;  // built without ALLOW_UPDATE
  fixed.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  VkCommandBuffer secondary = commands.BeginSecondary();
  blas.Build(secondary, fixed);
  commands.End(secondary);
  VkCommandBuffer primary = commands.Begin();
  procs.CmdExecuteCommands(primary, 1, &secondary);
  commands.Barrier(primary);
  blas.Update(primary, fixed);
  commands.End(primary);
  f.monitor().Expect(k03667);
  CHECK(commands.Submit(primary) == VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("a secondary executed by VkCommandBuffer") != std::string::npos);
}

TEST_CASE("history valid twin: builds and updates in secondary command buffers stay silent", "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Procs procs(device);
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = commands.BeginSecondary();
  blas.Build(build, Geometries(2));
  commands.End(build);
  VkCommandBuffer update = commands.BeginSecondary();
  blas.Update(update, Geometries(2));
  commands.End(update);
  VkCommandBuffer primary = commands.Begin();
  procs.CmdExecuteCommands(primary, 1, &build);
  commands.Barrier(primary);
  procs.CmdExecuteCommands(primary, 1, &update);
  commands.End(primary);
  CHECK(commands.Submit(primary) == VK_SUCCESS);
  CHECK(commands.Submit(primary) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: vkQueueSubmit2 applies and checks like vkQueueSubmit",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Procs procs(device);
  REQUIRE(procs.QueueSubmit2);
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Shape{});
  commands.End(update);
  f.monitor().Expect(k03667);
  // The update's source was never built; the layer skips the submission (the device has no synchronization2,
  // so a call passed down would be invalid of its own).
  CHECK(procs.Submit2(device.queue(), update) == VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("vkQueueSubmit2(): pSubmits[0].pCommandBufferInfos[0].commandBuffer") !=
        std::string::npos);
}

}  // namespace
}  // namespace asval_test
