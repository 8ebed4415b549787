// Family traces (issue 29): trace and ray-query work reads top-level structures that a build has executed on, in
// execution order. The firing cases are skipped by the monitor's VK_TRUE, so no invalid work reaches lavapipe; the
// valid twins run on it, are waited for, and must compute the ray's hit (the layer changes nothing the app computes).
#include <catch2/catch_test_macros.hpp>
#include <functional>

#include "on_test_driver.h"
#include "ray_program.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char kRayQueryBuilt[] = "VUID-RuntimeSpirv-OpRayQueryInitializeKHR-06352";
constexpr const char kTraceRayBuilt[] = "VUID-RuntimeSpirv-OpTraceRayKHR-06359";

TEST_CASE(
    "traces: a ray query dispatched over a top-level structure no build executed on (OpRayQueryInitializeKHR-06352)",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  Tlas never_built(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(never_built.handle());
  Commands commands(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(cb);  // skipped by the monitor's VK_TRUE: the ray never reads the unbuilt structure
  CHECK(f.monitor().Verify() == "");
  // The same structure pushed (vkCmdPushDescriptorSetKHR) rather than bound through a set.
  RayProgram pushing(device, RayProgram::Kind::kRayQuery, true);
  const VkCommandBuffer pushed =
      Recorded(commands, [&](VkCommandBuffer c) { pushing.Record(c, never_built.handle()); });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(pushed);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces: a ray-tracing pipeline traces a top-level structure no build executed on (OpTraceRayKHR-06359)",
          "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  Tlas never_built(device);
  RayProgram program(device, RayProgram::Kind::kTraceRays);
  program.Write(never_built.handle());
  Commands commands(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  f.monitor().Expect(kTraceRayBuilt);
  commands.Submit(cb);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "traces: execution order, not recording order: the build recorded first but submitted after the dispatch "
    "is reported",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  RayScene scene(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Commands commands(device);
  const VkCommandBuffer build = Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); });
  const VkCommandBuffer query = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(query);  // before the build's submission: skipped
  CHECK(f.monitor().Verify() == "");
  REQUIRE(commands.Submit(build) == VK_SUCCESS);  // waits for the queue
  program.Clear();
  REQUIRE(commands.Submit(query) == VK_SUCCESS);  // the same recording, now after the build: silent
  CHECK(program.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces: a draw whose fragment shader queries a top-level structure no build executed on (06352)",
          "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDrawDevice());
  vkkit::Device& device = f.device();
  Tlas never_built(device);
  Commands commands(device);
  RayProgram program(device, RayProgram::Kind::kDraw);
  program.Write(never_built.handle());
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); }));  // skipped (VK_TRUE)
  CHECK(f.monitor().Verify() == "");
  RayProgram pushing(device, RayProgram::Kind::kDraw, true);
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { pushing.Record(c, never_built.handle()); }));
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces valid twin: a draw queries a structure built before it, in its command buffer or an earlier one",
          "[integration][traces]") {
  HistoryFixture f(nullptr, {}, RayDrawDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  RayScene scene(device);
  RayProgram program(device, RayProgram::Kind::kDraw);
  program.Write(scene.tlas.handle());
  program.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) {
    scene.Build(commands, c);
    program.BarrierAfterBuild(c);
    program.Record(c);
  })) == VK_SUCCESS);
  CHECK(program.hit() == 1u);
  RayProgram pushing(device, RayProgram::Kind::kDraw, true);
  pushing.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { pushing.Record(c, scene.tlas.handle()); })) ==
          VK_SUCCESS);
  CHECK(pushing.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces valid twin: the trace reads a structure built earlier in execution order", "[integration][traces]") {
  HistoryFixture f(nullptr, {}, RayDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  RayScene scene(device);
  // Built and queried in one command buffer, the build's writes made visible to the query.
  RayProgram query(device, RayProgram::Kind::kRayQuery);
  query.Write(scene.tlas.handle());
  query.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) {
    scene.Build(commands, c);
    query.BarrierAfterBuild(c);
    query.Record(c);
  })) == VK_SUCCESS);
  CHECK(query.hit() == 1u);
  // Traced by a ray-tracing pipeline in a later submission.
  RayProgram trace(device, RayProgram::Kind::kTraceRays);
  trace.Write(scene.tlas.handle());
  trace.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { trace.Record(c); })) == VK_SUCCESS);
  CHECK(trace.hit() == 1u);
  // Descriptors rewritten before the trace: the set first named a structure never built.
  Tlas never_built(device);
  query.Write(never_built.handle());
  query.Write(scene.tlas.handle());
  query.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { query.Record(c); })) == VK_SUCCESS);
  CHECK(query.hit() == 1u);
  // Pushed rather than bound.
  RayProgram pushing(device, RayProgram::Kind::kRayQuery, true);
  pushing.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { pushing.Record(c, scene.tlas.handle()); })) ==
          VK_SUCCESS);
  CHECK(pushing.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces: a dispatch recorded in a secondary command buffer is judged where the primary executes it",
          "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  RayScene scene(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  RayProgram built(device, RayProgram::Kind::kRayQuery);
  built.Write(scene.tlas.handle());
  Tlas never_built(device);
  RayProgram unbuilt(device, RayProgram::Kind::kRayQuery);
  unbuilt.Write(never_built.handle());
  // The primary's own dispatch reads the built structure; the secondary's, after it, the one never built: the
  // secondary's binding follows the primary's in the executed recording.
  const VkCommandBuffer secondary = commands.BeginSecondary();
  unbuilt.Record(secondary);
  commands.End(secondary);
  const VkCommandBuffer primary = Recorded(commands, [&](VkCommandBuffer c) {
    built.Record(c);
    vkCmdExecuteCommands(c, 1, &secondary);
  });
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(primary);
  CHECK(f.monitor().Verify() == "");
  // Valid twin: a secondary recorded over the descriptor rewritten with the built structure (rewriting it
  // invalidated the recordings above, which are not submitted again).
  unbuilt.Write(scene.tlas.handle());
  const VkCommandBuffer secondary_twin = commands.BeginSecondary();
  unbuilt.Record(secondary_twin);
  commands.End(secondary_twin);
  const VkCommandBuffer twin = Recorded(commands, [&](VkCommandBuffer c) {
    built.Record(c);
    vkCmdExecuteCommands(c, 1, &secondary_twin);
  });
  unbuilt.Clear();
  REQUIRE(commands.Submit(twin) == VK_SUCCESS);
  CHECK(unbuilt.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces: descriptors written through an update template are followed", "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  Tlas never_built(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.WriteWithTemplate(never_built.handle());
  f.monitor().Expect(kRayQueryBuilt);
  commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); }));
  CHECK(f.monitor().Verify() == "");
  // Valid twin: the template rewrites the descriptor with a built structure before the recording.
  RayScene scene(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  program.WriteWithTemplate(scene.tlas.handle());
  program.Clear();
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); })) == VK_SUCCESS);
  CHECK(program.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

// The bottom levels under a traced top level: a scene built and waited for (the capture has read the top level's
// instances by the time the wait returned), and a ray-query program whose set names the top level.
struct TracedScene {
  explicit TracedScene(vkkit::Device& d) : device(d), commands(d), scene(d), program(d, RayProgram::Kind::kRayQuery) {
    REQUIRE(Run([&](VkCommandBuffer c) { scene.Build(commands, c); }) == VK_SUCCESS);
    program.Write(scene.tlas.handle());
  }
  // Records one command buffer and submits it (waited for).
  VkResult Run(const std::function<void(VkCommandBuffer)>& record) {
    return commands.Submit(Recorded(commands, record));
  }
  // `before`, the barrier, and the query (its output cleared first); a valid twin's query must hit.
  void QueryAfter(const std::function<void(VkCommandBuffer)>& before) {
    program.Clear();
    REQUIRE(Run([&](VkCommandBuffer c) {
              before(c);
              program.BarrierAfterBuild(c);
              program.Record(c);
            }) == VK_SUCCESS);
    CHECK(program.hit() == 1u);
  }
  // The query alone, expected to be reported (the monitor's VK_TRUE skips it: lavapipe never runs it).
  void QueryReported(Monitor& monitor, const char* id) {
    monitor.Expect(id);
    Run([&](VkCommandBuffer c) { program.Record(c); });
    CHECK(monitor.Verify() == "");
  }
  // Streaming out: `replacement` takes the old bottom level's place in a rebuild of the top level, waited for.
  void RebuildWith(Blas& replacement) {
    vkkit::Buffer instances = scene.tlas.MakeInstances({&replacement});
    REQUIRE(Run([&](VkCommandBuffer c) {
              replacement.Build(c, Shape{});
              commands.Barrier(c);
              scene.tlas.Record(c, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
            }) == VK_SUCCESS);
    device.Destroy(instances);
  }

  vkkit::Device& device;
  Commands commands;
  RayScene scene;
  RayProgram program;
};

TEST_CASE(
    "traces: a traced top level whose last build referenced a bottom level destroyed since is reported "
    "(ASVAL-Traces-BottomLevelInvalid)",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  TracedScene t(f.device());
  t.scene.blas.DestroyHandle();  // its storage stays: a driver that ran the query would still find its bytes
  t.QueryReported(f.monitor(), "ASVAL-Traces-BottomLevelInvalid");
}

TEST_CASE("traces valid twin: a bottom level destroyed once the traced top level was rebuilt without it stays silent",
          "[integration][traces]") {
  HistoryFixture f(nullptr, {}, RayDevice());
  TracedScene t(f.device());
  Blas replacement(t.device, t.scene.inputs);
  t.RebuildWith(replacement);
  t.scene.blas.DestroyHandle();
  t.QueryAfter([](VkCommandBuffer) {});
  // Rebuilt in the same command buffer as the query, after another bottom level went: what that build referenced is
  // not known before it completes (its references were judged there: pInfos-06707), so nothing is said.
  Blas third(t.device, t.scene.inputs);
  vkkit::Buffer third_instances = t.scene.tlas.MakeInstances({&third});
  REQUIRE(t.Run([&](VkCommandBuffer c) { third.Build(c, Shape{}); }) == VK_SUCCESS);
  replacement.DestroyHandle();  // the top level still references it, until the rebuild below runs
  t.QueryAfter([&](VkCommandBuffer c) {
    t.scene.tlas.Record(c, third_instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  t.device.Destroy(third_instances);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "traces: a traced top level whose last build referenced a bottom level whose memory was freed since is reported "
    "(ASVAL-Traces-BottomLevelInvalid)",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  TracedScene t(f.device());
  t.scene.blas.FreeStorageMemory();  // the structure and its buffer stay alive
  t.QueryReported(f.monitor(), "ASVAL-Traces-BottomLevelInvalid");
}

TEST_CASE("traces valid twin: a bottom level's memory freed once the traced top level was rebuilt without it",
          "[integration][traces]") {
  HistoryFixture f(nullptr, {}, RayDevice());
  TracedScene t(f.device());
  Blas replacement(t.device, t.scene.inputs);
  t.RebuildWith(replacement);
  t.scene.blas.FreeStorageMemory();  // alive, unreferenced: its memory may go
  t.QueryAfter([](VkCommandBuffer) {});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("traces: a referenced bottom level whose storage buffer was destroyed is not judged, and is counted",
          "[integration][traces]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}}, RayDevice());
  {
    TracedScene t(f.device());
    t.scene.blas.DestroyStorageBuffer();  // its memory stays: engines relocate structures so
    t.QueryAfter([](VkCommandBuffer) {});
    CHECK(f.monitor().Verify() == "");
  }
  f.Close();
  bool counted = false;
  for (const std::string& line : report.Lines()) {
    counted |= line.find("ASVAL-Traces-Summary") != std::string::npos &&
               line.find("bottom_level_unknown=1") != std::string::npos;
  }
  CHECK(counted);
}

Shape Geometries(uint32_t count) {
  Shape shape;
  shape.geometries = count;
  return shape;
}

TEST_CASE(
    "traces: a traced top level whose bottom level was rebuilt since with another geometry count warns "
    "(ASVAL-Traces-BottomLevelChanged)",
    "[integration][traces]") {
  HistoryFixture f("traces", {}, RayDevice());
  TracedScene t(f.device());
  // The bottom level rebuilt with two geometries; the top level, built over its one geometry, is not rebuilt.
  REQUIRE(t.Run([&](VkCommandBuffer c) { t.scene.blas.Build(c, Geometries(2)); }) == VK_SUCCESS);
  t.QueryReported(f.monitor(), "ASVAL-Traces-BottomLevelChanged");
  // A rebuild with three geometries in the command buffer of the query, before it: warned in execution order.
  f.monitor().Expect("ASVAL-Traces-BottomLevelChanged");
  t.Run([&](VkCommandBuffer c) {
    t.scene.blas.Build(c, Geometries(3));
    t.commands.Barrier(c);
    t.program.Record(c);
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "traces valid twin: a bottom level refitted, rebuilt with the same layout, or rebuilt before the top level stays "
    "silent",
    "[integration][traces]") {
  HistoryFixture f(nullptr, {}, RayDevice());
  TracedScene t(f.device());
  RayScene& scene = t.scene;
  // Refitted (an update keeps the geometries), then rebuilt with the same layout, without the top level.
  t.QueryAfter([&](VkCommandBuffer c) { scene.blas.Update(c, Shape{}); });
  t.QueryAfter([&](VkCommandBuffer c) { scene.blas.Build(c, Shape{}); });
  // Rebuilt with two geometries and the top level rebuilt after it, in one submission and in two.
  t.QueryAfter([&](VkCommandBuffer c) {
    scene.blas.Build(c, Geometries(2));
    t.commands.Barrier(c);
    scene.tlas.Record(c, scene.instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  REQUIRE(t.Run([&](VkCommandBuffer c) { scene.blas.Build(c, Shape{}); }) == VK_SUCCESS);
  t.QueryAfter([&](VkCommandBuffer c) {
    scene.tlas.Record(c, scene.instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  t.QueryAfter([](VkCommandBuffer) {});
  CHECK(f.monitor().Verify() == "");
}

// Family lifetime over traces: a structure a pending trace or dispatch reads through its descriptors is in use. The
// dispatch is held pending by a timeline wait the host signals after the destroy.
vkkit::DeviceOptions RayTimelineDevice() {
  vkkit::DeviceOptions options = RayDevice();
  options.timeline_semaphore = true;
  return options;
}

TEST_CASE(
    "lifetime: a top-level structure destroyed while a pending ray query reads it is reported "
    "(accelerationStructure-02442)",
    "[integration][lifetime][traces]") {
  HistoryFixture f("lifetime", {}, RayTimelineDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  RayScene scene(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Timeline gate(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);  // runs once the host signals 1
  f.monitor().Expect("VUID-vkDestroyAccelerationStructureKHR-accelerationStructure-02442");
  scene.tlas.DestroyHandle();  // skipped by the monitor: the layer makes it once the dispatch completed
  CHECK(f.monitor().Verify() == "");
  CHECK(gate.HostSignal(1) == VK_SUCCESS);
  CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  CHECK(program.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("lifetime valid twin: a top-level structure destroyed after the ray query reading it completed stays silent",
          "[integration][lifetime][traces]") {
  HistoryFixture f(nullptr, {}, RayTimelineDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  RayScene scene(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Timeline gate(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  REQUIRE(SubmitOn(device.queue(), cb, gate, 0, 1) == VK_SUCCESS);
  REQUIRE(gate.HostWait(1, 10ull * 1000 * 1000 * 1000) == VK_SUCCESS);  // completed, learned on the host
  scene.tlas.DestroyHandle();
  CHECK(program.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

// The top level's storage, which the pending query reads through it: its buffer destroyed, or its memory freed.
// Reported, and kept back by the layer until the query completed (the monitor's VK_TRUE), so lavapipe never reads
// freed memory; the twins do the same once the query completed.
void StorageGoesWhileQueryPending(bool pending, const std::function<void(Tlas&)>& goes, const char* vuid) {
  HistoryFixture f(pending ? "lifetime" : nullptr, {}, RayTimelineDevice());
  vkkit::Device& device = f.device();
  Commands commands(device);
  RayScene scene(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Timeline gate(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  if (pending) {
    REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);  // runs once the host signals 1
    f.monitor().Expect(vuid);
    goes(scene.tlas);
    CHECK(f.monitor().Verify() == "");
    CHECK(gate.HostSignal(1) == VK_SUCCESS);
    CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  } else {
    REQUIRE(SubmitOn(device.queue(), cb, gate, 0, 1) == VK_SUCCESS);
    REQUIRE(gate.HostWait(1, 10ull * 1000 * 1000 * 1000) == VK_SUCCESS);  // completed, learned on the host
    goes(scene.tlas);
  }
  CHECK(program.hit() == 1u);
  scene.tlas.DestroyHandle();  // before its memory goes, where the test kept the memory
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "lifetime: the storage buffer of a top-level structure a pending ray query reads, destroyed, is reported "
    "(buffer-00922)",
    "[integration][lifetime][traces]") {
  StorageGoesWhileQueryPending(
      true, [](Tlas& tlas) { tlas.DestroyStorageBuffer(); }, "VUID-vkDestroyBuffer-buffer-00922");
}

TEST_CASE("lifetime: the memory of a top-level structure a pending ray query reads, freed, is reported (memory-00677)",
          "[integration][lifetime][traces]") {
  StorageGoesWhileQueryPending(
      true, [](Tlas& tlas) { tlas.FreeStorageMemory(); }, "VUID-vkFreeMemory-memory-00677");
}

TEST_CASE("lifetime valid twin: a traced top level's storage buffer destroyed, or memory freed, after the query",
          "[integration][lifetime][traces]") {
  StorageGoesWhileQueryPending(
      false, [](Tlas& tlas) { tlas.DestroyStorageBuffer(); }, nullptr);
  StorageGoesWhileQueryPending(
      false, [](Tlas& tlas) { tlas.FreeStorageMemory(); }, nullptr);
}

// A bottom level the pending ray query traverses through the top level (whose build, completed before the query's
// submission, referenced it): destroyed, or its memory freed. Reported at the destroy (family traces) and kept back by
// the layer until the query completed (the monitor's VK_TRUE), so lavapipe never traverses freed memory. The query is
// held pending by the test driver (submission_hold.h), below asval: asval sees a batch with no wait, applied at once,
// as a busy GPU's would be (a wait asval sees defers the batch, judged when it is applied: traces_test's submit-time
// cases). `rebuilt`: the top level was rebuilt without it (waited for) before the query's submission; `pending`
// false: the query completed (waited for) before the destroy.
void BottomLevelGoesWhileQueryPending(bool pending, bool rebuilt, const std::function<void(Blas&)>& goes,
                                      const char* id) {
  OnTestDriver on_test_driver;
  HistoryFixture f(id ? "lifetime,traces" : nullptr, {}, RayTimelineDevice());
  vkkit::Device& device = f.device();
  HeldSubmissions held(device);
  Commands commands(device);
  RayScene scene(device);
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) { scene.Build(commands, c); })) == VK_SUCCESS);
  Blas replacement(device, scene.inputs);
  if (rebuilt) {
    vkkit::Buffer instances = scene.tlas.MakeInstances({&replacement});
    REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) {
      replacement.Build(c, Shape{});
      commands.Barrier(c);
      scene.tlas.Record(c, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    })) == VK_SUCCESS);
    device.Destroy(instances);
  }
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { program.Record(c); });
  REQUIRE((pending ? held.SubmitHeld(cb) : held.SubmitAndWait(cb)) == VK_SUCCESS);
  if (id) f.monitor().Expect(id);
  goes(scene.blas);
  CHECK(f.monitor().Verify() == "");
  CHECK(held.Release() == VK_SUCCESS);
  CHECK(program.hit() == 1u);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "traces: a bottom level destroyed while a pending ray query traverses it through the top level is reported "
    "(ASVAL-Traces-BottomLevelInvalid)",
    "[integration][lifetime][traces]") {
  BottomLevelGoesWhileQueryPending(
      true, false, [](Blas& blas) { blas.DestroyHandle(); }, "ASVAL-Traces-BottomLevelInvalid");
}

TEST_CASE(
    "traces: a bottom level's memory freed while a pending ray query traverses it through the top level is reported "
    "(ASVAL-Traces-BottomLevelInvalid)",
    "[integration][lifetime][traces]") {
  BottomLevelGoesWhileQueryPending(
      true, false, [](Blas& blas) { blas.FreeStorageMemory(); }, "ASVAL-Traces-BottomLevelInvalid");
}

TEST_CASE(
    "traces valid twin: a bottom level destroyed or its memory freed after the query traversing it completed, or "
    "while a query over a top level rebuilt without it is pending, or its buffer destroyed (memory kept), stays "
    "silent",
    "[integration][lifetime][traces]") {
  BottomLevelGoesWhileQueryPending(
      false, false, [](Blas& blas) { blas.DestroyHandle(); }, nullptr);
  BottomLevelGoesWhileQueryPending(
      false, false, [](Blas& blas) { blas.FreeStorageMemory(); }, nullptr);
  BottomLevelGoesWhileQueryPending(
      true, true, [](Blas& blas) { blas.DestroyHandle(); }, nullptr);
  BottomLevelGoesWhileQueryPending(
      true, true, [](Blas& blas) { blas.FreeStorageMemory(); }, nullptr);
  BottomLevelGoesWhileQueryPending(
      true, false, [](Blas& blas) { blas.DestroyStorageBuffer(); }, nullptr);
}

TEST_CASE(
    "traces valid twin: a top level cloned over after the pending query read it, in the query's submission, is not "
    "taken for what the query read: a bottom level the clone's source references, destroyed then, stays silent",
    "[integration][lifetime][traces]") {
  OnTestDriver on_test_driver;
  HistoryFixture f(nullptr, {}, RayTimelineDevice());
  vkkit::Device& device = f.device();
  HeldSubmissions held(device);
  Commands commands(device);
  RayScene scene(device);
  Blas replacement(device, scene.inputs);
  Tlas other(device);
  vkkit::Buffer instances = other.MakeInstances({&replacement});
  REQUIRE(commands.Submit(Recorded(commands, [&](VkCommandBuffer c) {
    scene.Build(commands, c);
    replacement.Build(c, Shape{});
    commands.Barrier(c);
    other.Record(c, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  })) == VK_SUCCESS);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  // The query reads the top level referencing scene.blas; the clone then makes it reference `replacement`.
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) {
    program.Record(c);
    commands.Barrier(c);
    CmdCopy(device, c, other.handle(), scene.tlas.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  });
  REQUIRE(held.SubmitHeld(cb) == VK_SUCCESS);
  replacement.DestroyHandle();  // what the clone's source references: not what the query traverses
  CHECK(f.monitor().Verify() == "");
  CHECK(held.Release() == VK_SUCCESS);
  CHECK(program.hit() == 1u);
  device.Destroy(instances);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
