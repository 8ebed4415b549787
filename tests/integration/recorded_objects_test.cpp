// Family lifetime (issue 29), at submission: a command buffer whose acceleration-structure command recorded a
// structure or a buffer (by the address it reads) that was destroyed since is invalid, and submitting it is
// reported (vkQueueSubmit-pCommandBuffers-00070, vkQueueSubmit2-commandBuffer-03874). The monitor's VK_TRUE skips
// the reported submissions: nothing invalid reaches lavapipe.
#include <catch2/catch_test_macros.hpp>
#include <memory>
#include <string>
#include <vector>

#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char kSubmitInvalid[] = "VUID-vkQueueSubmit-pCommandBuffers-00070";
constexpr const char kSubmit2Invalid[] = "VUID-vkQueueSubmit2-commandBuffer-03874";
constexpr const char kUpdateOfUnbuilt[] = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667";

TEST_CASE(
    "recorded objects: a command buffer submitted after a structure its build recorded was destroyed is reported "
    "(pCommandBuffers-00070)",
    "[integration][lifetime]") {
  HistoryFixture f("lifetime");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
  blas.Recreate();  // the structure recorded goes; a new one (perhaps with the same handle value) is made
  f.monitor().Expect(kSubmitInvalid);
  CHECK(commands.Submit(cb) == VK_ERROR_VALIDATION_FAILED_EXT);
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("destroyed since") != std::string::npos);
  CHECK(messages[0].text.find("dstAccelerationStructure") != std::string::npos);
}

TEST_CASE(
    "recorded objects: a command buffer submitted after the buffer holding its build's vertices was destroyed is "
    "reported once (pCommandBuffers-00070)",
    "[integration][lifetime]") {
  HistoryFixture f("lifetime");
  vkkit::Device& device = f.device();
  auto inputs = std::make_unique<Inputs>(device);
  Blas blas(device, *inputs);
  Commands commands(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) {
    blas.Build(c, Shape{});
    commands.Barrier(c);
    blas.Build(c, Shape{});  // the same buffer again: one finding per command buffer and buffer
  });
  inputs.reset();
  f.monitor().Expect(kSubmitInvalid);
  CHECK(commands.Submit(cb) == VK_ERROR_VALIDATION_FAILED_EXT);
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("vertexData") != std::string::npos);
}

TEST_CASE(
    "recorded objects: a secondary command buffer's build whose structure was destroyed invalidates the primary "
    "executing it, submitted with vkQueueSubmit2 (commandBuffer-03874)",
    "[integration][lifetime]") {
  HistoryFixture f("lifetime");
  vkkit::Device& device = f.device();
  Procs procs(device);
  REQUIRE(procs.QueueSubmit2);
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  const VkCommandBuffer secondary = commands.BeginSecondary();
  blas.Build(secondary, Shape{});
  commands.End(secondary);
  const VkCommandBuffer primary = commands.Begin();
  procs.CmdExecuteCommands(primary, 1, &secondary);
  commands.End(primary);
  blas.DestroyHandle();
  f.monitor().Expect(kSubmit2Invalid);
  CHECK(procs.Submit2(device.queue(), primary) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "recorded objects valid twin: command buffers recorded after the structures and buffers they name were made, "
    "and objects destroyed that no recording names, stay silent",
    "[integration][lifetime]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Commands commands(device);
  auto inputs = std::make_unique<Inputs>(device);
  Blas blas(device, *inputs);
  // Built, waited for, then its inputs and structure replaced and the command buffer recorded again.
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); })) == VK_SUCCESS);
  inputs = std::make_unique<Inputs>(device);
  blas.SetInputs(*inputs);
  blas.Recreate();  // the new structure may reuse the handle value: recorded after, it is the one named
  const VkCommandBuffer again = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
  // Objects no recording names, destroyed after it.
  {
    Inputs unrelated_inputs(device);
    Blas unrelated(device, unrelated_inputs);
  }
  CHECK(commands.Submit(again) == VK_SUCCESS);
  CHECK(commands.Submit(again) == VK_SUCCESS);  // submitted again: still valid
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "recorded objects: a recorded structure destroyed longer ago than the layer remembers is not judged, and is "
    "counted",
    "[integration][lifetime]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}});
  {
    vkkit::Device& device = f.device();
    Inputs inputs(device);
    Blas blas(device, inputs);
    Blas never_built(device, inputs);
    Commands commands(device);
    // The update of a structure never built is reported (history), so that the monitor's VK_TRUE keeps the
    // submission, and its stale handle, from the driver.
    const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) {
      blas.Build(c, Shape{});
      never_built.Update(c, Shape{});
    });
    blas.DestroyHandle();
    // More destroys than the layer keeps (ObjectLifetimes::kCapacity, 256): the one above is forgotten.
    Blas churn(device, inputs);
    for (int i = 0; i < 300; ++i) churn.Recreate();
    f.monitor().Expect(kUpdateOfUnbuilt);
    CHECK(commands.Submit(cb) == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(f.monitor().Verify() == "");  // nothing about the forgotten structure
  }
  f.Close();
  bool counted = false;
  for (const std::string& line : report.Lines()) {
    counted |= line.find("ASVAL-Lifetime-Summary") != std::string::npos &&
               line.find("recorded_forgotten=1") != std::string::npos;
  }
  CHECK(counted);
}

}  // namespace
}  // namespace asval_test
