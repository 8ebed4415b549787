// Family traces (issue 29) through descriptor buffers (VK_EXT_descriptor_buffer): the structure a ray query reads is
// named by descriptor bytes the app got from vkGetDescriptorEXT and wrote into a host-visible descriptor buffer. The
// layer reads those bytes at submission and judges the structure they were made from. Firing cases are skipped by
// the monitor's VK_TRUE; the valid twins run on lavapipe and must compute the ray's hit.
#include <catch2/catch_test_macros.hpp>
#include <string>

#include "on_test_driver.h"
#include "ray_program.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char kRayQueryBuilt[] = "VUID-RuntimeSpirv-OpRayQueryInitializeKHR-06352";
constexpr const char kUpdateOfUnbuilt[] = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667";

TEST_CASE(
    "traces: a ray query reads, through a descriptor buffer, a top-level structure no build executed on "
    "(OpRayQueryInitializeKHR-06352)",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDescriptorBufferDevice());
  vkkit::Device& device = f.device();
  Tlas never_built(device);
  DescriptorBufferRayQuery program(device);
  program.Write(never_built.address());
  Commands commands(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(cb);  // skipped by the monitor's VK_TRUE: the ray never reads the unbuilt structure
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("descriptor buffer") != std::string::npos);
}

TEST_CASE(
    "traces valid twin: descriptor-buffer bytes of a built top level, and bytes rewritten before the submission "
    "from an unbuilt structure to a built one, stay silent and the ray hits",
    "[integration][traces]") {
  HistoryFixture f(nullptr, {}, RayDescriptorBufferDevice());
  vkkit::Device& device = f.device();
  RayScene scene(device);
  Tlas never_built(device);
  DescriptorBufferRayQuery program(device);
  Commands commands(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  // Recorded while the bytes name the unbuilt structure: the bytes are what the device reads when it executes.
  program.Write(never_built.address());
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  program.Write(scene.tlas.address());
  program.Clear();
  CHECK(commands.Submit(cb) == VK_SUCCESS);
  CHECK(program.hit() == 1);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces: descriptor-buffer bytes that no vkGetDescriptorEXT made are not judged, and are counted",
          "[integration][traces]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}}, RayDescriptorBufferDevice());
  {
    vkkit::Device& device = f.device();
    RayScene scene(device);
    DescriptorBufferRayQuery program(device);
    Commands commands(device);
    REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
    program.Write(scene.tlas.address());
    program.Scribble(0x5a);  // the app's own bytes over binding 0: what they name is unknown
    // The update of a structure never built in the same command buffer is reported (history), so that the monitor's
    // VK_TRUE keeps the submission, and the bytes no driver made, from lavapipe.
    Blas never_built(device, scene.inputs);
    const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) {
      never_built.Update(c, Shape{});
      program.Record(c);
    });
    f.monitor().Expect(kUpdateOfUnbuilt);
    CHECK(commands.Submit(cb) == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(f.monitor().Verify() == "");  // nothing about the descriptor
  }
  f.Close();
  bool counted = false;
  for (const std::string& line : report.Lines()) {
    counted |=
        line.find("ASVAL-Traces-Summary") != std::string::npos && line.find("unknown_structure=1") != std::string::npos;
  }
  CHECK(counted);
}

// A structure a pending descriptor-buffer ray query reads: the top level its bytes name, or the bottom level it
// traverses through that top level. Destroyed while the query is held pending by the test driver below asval
// (tests/driver/submission_hold.h), reported and kept back by the layer until the query completed (the monitor's
// VK_TRUE); or, `pending` false, once the query completed (silent). The bytes are read at the destroy (lifetime) and
// at the submission (the top levels kept with the batch in flight: traced_tops.h).
void GoesWhileDescriptorBufferQueryPending(bool pending, bool bottom, const char* id) {
  OnTestDriver on_test_driver;
  vkkit::DeviceOptions options = RayDescriptorBufferDevice();
  options.timeline_semaphore = true;  // the test driver's hold waits on a timeline semaphore
  HistoryFixture f(id ? "lifetime,traces" : nullptr, {}, options);
  vkkit::Device& device = f.device();
  HeldSubmissions held(device);
  RayScene scene(device);
  DescriptorBufferRayQuery program(device);
  Commands commands(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  program.Write(scene.tlas.address());
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  REQUIRE((pending ? held.SubmitHeld(cb) : held.SubmitAndWait(cb)) == VK_SUCCESS);
  if (id) f.monitor().Expect(id);
  if (bottom) {
    scene.blas.DestroyHandle();
  } else {
    scene.tlas.DestroyHandle();
  }
  CHECK(f.monitor().Verify() == "");
  CHECK(held.Release() == VK_SUCCESS);
  CHECK(program.hit() == 1);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "lifetime: a top-level structure destroyed while a pending ray query reads it through a descriptor buffer is "
    "reported (accelerationStructure-02442)",
    "[integration][lifetime][traces]") {
  GoesWhileDescriptorBufferQueryPending(true, false,
                                        "VUID-vkDestroyAccelerationStructureKHR-accelerationStructure-02442");
}

TEST_CASE(
    "traces: a bottom level destroyed while a pending ray query traverses it through a top level named by "
    "descriptor-buffer bytes is reported (ASVAL-Traces-BottomLevelInvalid)",
    "[integration][lifetime][traces]") {
  GoesWhileDescriptorBufferQueryPending(true, true, "ASVAL-Traces-BottomLevelInvalid");
}

TEST_CASE(
    "lifetime valid twin: the top level and the bottom level a descriptor-buffer ray query read, destroyed once it "
    "completed, stay silent",
    "[integration][lifetime][traces]") {
  GoesWhileDescriptorBufferQueryPending(false, false, nullptr);
  GoesWhileDescriptorBufferQueryPending(false, true, nullptr);
}

}  // namespace
}  // namespace asval_test
