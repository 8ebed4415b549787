// Build history through the command-buffer features that make one recording execute more than once:
// VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT command buffers pending twice, a secondary executed twice by
// one vkCmdExecuteCommands, and a secondary re-recorded between two submissions of a primary that executes it.
//
// Why a finding is (or is not) expected, per the specification:
// - The update rules (VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758 and its siblings, primitiveCount-03769)
//   compare an update with what was specified "when srcAccelerationStructure was last built": a condition on
//   the state when the command executes. Every submission executes the command buffer's commands again (a
//   simultaneous-use command buffer pending twice executes them twice; a secondary named twice in
//   pCommandBuffers executes twice), so each execution is checked against the history left by everything
//   submitted before it, including the earlier, still pending, submission of the same command buffer.
// - A submission the layer skips (the monitor returns VK_TRUE) never executes: it leaves the history as it was,
//   so resubmitting the same invalid command buffer violates the rule again and is reported again.
// - A secondary that appears twice in one vkCmdExecuteCommands must have been recorded with
//   SIMULTANEOUS_USE (VUID-vkCmdExecuteCommands-pCommandBuffers-00093), and so must a primary submitted while
//   it is pending (VUID-vkQueueSubmit-pCommandBuffers-00071).
// - Re-recording a secondary moves every primary it was recorded into to the invalid state (command buffer
//   lifecycle: "If a secondary moves to any state other than executable, all primary buffers it is linked to
//   move to the invalid state"), so a valid program records the primary again, and the history must follow
//   the new recording of the secondary.
//
// Synchronization: every command buffer here starts with an AS-build barrier (and separates its own builds
// with one), whose first scope covers everything earlier in submission order, including the other pending
// submission of the same command buffer; the structure and its scratch are never written concurrently.
//
// Valid programs keep every family on; invalid ones narrow the fixture to "history" and assert the exact VUID.
#include <catch2/catch_test_macros.hpp>

#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* k03758 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";
constexpr const char* k03769 = "VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769";

Shape Geometries(uint32_t n) {
  Shape s;
  s.geometries = n;
  return s;
}

bool Contains(const std::string& text, const char* what) { return text.find(what) != std::string::npos; }

// vkBeginCommandBuffer with `flags` (implicitly resetting `cb`: the pool has RESET_COMMAND_BUFFER_BIT).
void BeginRecording(VkCommandBuffer cb, VkCommandBufferLevel level, VkCommandBufferUsageFlags flags) {
  VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = flags;
  if (level == VK_COMMAND_BUFFER_LEVEL_SECONDARY) begin.pInheritanceInfo = &inheritance;
  vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
}

// A new command buffer from `commands`' pool (freed when the pool is destroyed), begun with `flags`.
VkCommandBuffer Begin(vkkit::Device& device, Commands& commands, VkCommandBufferLevel level,
                      VkCommandBufferUsageFlags flags) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = commands.pool();
  alloc.level = level;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateCommandBuffers(device.handle(), &alloc, &cb), "vkAllocateCommandBuffers");
  BeginRecording(cb, level, flags);
  return cb;
}

VkCommandBuffer BeginSimultaneous(vkkit::Device& device, Commands& commands,
                                  VkCommandBufferLevel level = VK_COMMAND_BUFFER_LEVEL_PRIMARY) {
  return Begin(device, commands, level, VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
}

// Submits `cbs` as one batch and does not wait: they stay pending.
VkResult SubmitPending(vkkit::Device& device, const std::vector<VkCommandBuffer>& cbs) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = static_cast<uint32_t>(cbs.size());
  submit.pCommandBuffers = cbs.data();
  return vkQueueSubmit(device.queue(), 1, &submit, VK_NULL_HANDLE);
}

// Waits for the queue when it goes out of scope (declared after Commands, so before the pool is destroyed):
// nothing is left pending, even when a check fails between a pending submission and the next wait.
class IdleOnExit {
 public:
  explicit IdleOnExit(vkkit::Device& device) : device_(device) {}
  ~IdleOnExit() { vkQueueWaitIdle(device_.queue()); }
  IdleOnExit(const IdleOnExit&) = delete;
  IdleOnExit& operator=(const IdleOnExit&) = delete;

 private:
  vkkit::Device& device_;
};

// ---- simultaneous-use command buffers pending twice ------------------------------------------------------------

// A is built with 1 geometry, then a simultaneous-use command buffer rebuilds it with 2 geometries and is
// submitted twice without a wait (both pending); the update recorded elsewhere must match the 2-geometry build.
struct PendingTwiceSetup {
  explicit PendingTwiceSetup(HistoryFixture& f)
      : device(f.device()), inputs(device), blas(device, inputs), commands(device), idle(device) {
    VkCommandBuffer first = commands.Begin();
    blas.Build(first, Geometries(1));
    commands.End(first);
    REQUIRE(commands.Submit(first) == VK_SUCCESS);  // waited for
    rebuild = BeginSimultaneous(device, commands);
    commands.Barrier(rebuild);
    blas.Build(rebuild, Geometries(2));
    commands.End(rebuild);
  }
  VkCommandBuffer RecordUpdate(uint32_t geometries) {
    VkCommandBuffer cb = commands.Begin();
    commands.Barrier(cb);
    blas.Update(cb, Geometries(geometries));
    commands.End(cb);
    return cb;
  }

  vkkit::Device& device;
  Inputs inputs;
  Blas blas;
  Commands commands;
  IdleOnExit idle;
  VkCommandBuffer rebuild = VK_NULL_HANDLE;
};

TEST_CASE("history valid twin: a simultaneous-use build pending twice, then an update matching it, stays silent",
          "[integration][history][command-buffers]") {
  HistoryFixture f;
  PendingTwiceSetup s(f);
  VkCommandBuffer update = s.RecordUpdate(2);
  CHECK(SubmitPending(s.device, {s.rebuild}) == VK_SUCCESS);
  CHECK(SubmitPending(s.device, {s.rebuild}) == VK_SUCCESS);  // pending twice
  CHECK(s.commands.Submit(update) == VK_SUCCESS);              // waits for the queue: all three ran
  // And once more, both copies of the rebuild in one batch ahead of the update.
  CHECK(s.commands.Submit({s.rebuild, s.rebuild, update}) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: an update after a simultaneous-use build pending twice is checked against that build (03758)",
          "[integration][history][command-buffers]") {
  HistoryFixture f("history");
  PendingTwiceSetup s(f);
  VkCommandBuffer update = s.RecordUpdate(1);  // matches only the 1-geometry build that ran before both
  CHECK(SubmitPending(s.device, {s.rebuild}) == VK_SUCCESS);
  CHECK(SubmitPending(s.device, {s.rebuild}) == VK_SUCCESS);
  f.monitor().Expect(k03758);
  CHECK(s.commands.Submit(update) == VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].id_name == k03758);
  CHECK(Contains(messages[0].text, "geometryCount is 1"));
  CHECK(Contains(messages[0].text, "with geometryCount 2"));
}

// A simultaneous-use command buffer that contradicts the history: it updates A with 1 primitive per geometry
// while A's last executed build had 2. Both submissions violate primitiveCount-03769 (see the top of the file:
// the first one is skipped, never executes, and leaves A's history as it was, so the second executes the same
// update against the same build) and each is reported.
TEST_CASE("history: a simultaneous-use command buffer contradicting the history is reported at each submission",
          "[integration][history][command-buffers]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  IdleOnExit idle(device);
  Shape built;
  built.triangles = 2;
  built.max_vertex = 5;
  Shape fewer = built;  // only primitiveCount differs (maxVertex stays 5: no 03764)
  fewer.triangles = 1;
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, built);
  commands.End(build);
  REQUIRE(commands.Submit(build) == VK_SUCCESS);
  VkCommandBuffer update = BeginSimultaneous(device, commands);
  commands.Barrier(update);
  blas.Update(update, fewer);
  commands.End(update);

  SECTION("in two vkQueueSubmit calls") {
    for (int submission = 0; submission < 2; ++submission) {
      f.monitor().Expect(k03769);
      CHECK(SubmitPending(device, {update}) == VK_ERROR_VALIDATION_FAILED_EXT);
      std::vector<Message> messages = f.monitor().Take();
      REQUIRE(messages.size() == 1);
      CHECK(messages[0].id_name == k03769);
      CHECK(Contains(messages[0].text, "vkQueueSubmit(): pSubmits[0].pCommandBuffers[0]"));
    }
  }
  SECTION("twice in one batch") {
    // The first copy is reported. How many findings the second copy adds is not pinned here: it executes after
    // the first copy's (invalid) update, and the specification does not say what an invalid update leaves as
    // "last built"; the layer today adopts the update's own parameters (its history-apply step), which
    // reports the root cause once rather than again for each later copy. Either way the batch is skipped.
    f.monitor().Expect(k03769);
    CHECK(SubmitPending(device, {update, update}) == VK_ERROR_VALIDATION_FAILED_EXT);
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(!messages.empty());
    CHECK(messages.size() <= 2);
    for (const Message& m : messages) CHECK(m.id_name == k03769);
    CHECK(Contains(messages[0].text, "vkQueueSubmit(): pSubmits[0].pCommandBuffers[0]"));
  }
  // Nothing was executed: the update that matches the build still is valid.
  VkCommandBuffer valid = commands.Begin();
  commands.Barrier(valid);
  blas.Update(valid, built);
  commands.End(valid);
  CHECK(commands.Submit(valid) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

// A simultaneous-use command buffer that updates A as built with 1 geometry and then rebuilds it with 2: its
// first submission is valid; a second one submitted while the first is pending executes after the first's
// 2-geometry build, and its update contradicts that build.
struct UpdateThenRebuild {
  explicit UpdateThenRebuild(HistoryFixture& f)
      : device(f.device()), inputs(device), blas(device, inputs), commands(device), idle(device) {
    VkCommandBuffer first = commands.Begin();
    blas.Build(first, Geometries(1));
    commands.End(first);
    REQUIRE(commands.Submit(first) == VK_SUCCESS);
    cb = BeginSimultaneous(device, commands);
    commands.Barrier(cb);
    blas.Update(cb, Geometries(1));
    commands.Barrier(cb);
    blas.Build(cb, Geometries(2));
    commands.End(cb);
  }

  vkkit::Device& device;
  Inputs inputs;
  Blas blas;
  Commands commands;
  IdleOnExit idle;
  VkCommandBuffer cb = VK_NULL_HANDLE;
};

TEST_CASE("history: a simultaneous-use command buffer's second pending submission is checked after its first (03758)",
          "[integration][history][command-buffers]") {
  HistoryFixture f("history");
  UpdateThenRebuild s(f);
  CHECK(SubmitPending(s.device, {s.cb}) == VK_SUCCESS);  // valid, and pending from here on
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect(k03758);
  CHECK(SubmitPending(s.device, {s.cb}) == VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].id_name == k03758);
  CHECK(Contains(messages[0].text, "geometryCount is 1"));
  CHECK(Contains(messages[0].text, "with geometryCount 2"));
  REQUIRE(vkQueueWaitIdle(s.device.queue()) == VK_SUCCESS);
}

TEST_CASE("history valid twin: a 1-geometry build submitted between the two pending submissions stays silent",
          "[integration][history][command-buffers]") {
  HistoryFixture f;
  UpdateThenRebuild s(f);
  VkCommandBuffer restore = s.commands.Begin();  // not simultaneous-use: submitted once
  s.commands.Barrier(restore);
  s.blas.Build(restore, Geometries(1));
  s.commands.End(restore);
  CHECK(SubmitPending(s.device, {s.cb}) == VK_SUCCESS);
  CHECK(SubmitPending(s.device, {restore}) == VK_SUCCESS);
  CHECK(SubmitPending(s.device, {s.cb}) == VK_SUCCESS);
  REQUIRE(vkQueueWaitIdle(s.device.queue()) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

// ---- a secondary executed twice by one vkCmdExecuteCommands -----------------------------------------------------

TEST_CASE("history valid twin: a secondary updating a structure, executed twice in one primary, stays silent",
          "[integration][history][command-buffers]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Procs procs(device);
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Geometries(2));  // with ALLOW_UPDATE (Shape's default flags)
  commands.End(build);
  REQUIRE(commands.Submit(build) == VK_SUCCESS);
  VkCommandBuffer secondary = BeginSimultaneous(device, commands, VK_COMMAND_BUFFER_LEVEL_SECONDARY);
  commands.Barrier(secondary);
  blas.Update(secondary, Geometries(2));
  commands.End(secondary);
  VkCommandBuffer primary = commands.Begin();
  const VkCommandBuffer twice[2] = {secondary, secondary};
  procs.CmdExecuteCommands(primary, 2, twice);  // two updates of A in a row
  commands.End(primary);
  CHECK(commands.Submit(primary) == VK_SUCCESS);
  CHECK(commands.Submit(primary) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

// The secondary updates A as built with 1 geometry, then rebuilds it with 2: the first execution is valid, the
// second's update contradicts the first execution's build. Exactly one finding, for the second execution.
TEST_CASE("history: the second execution of a secondary in one primary is checked after the first (03758)",
          "[integration][history][command-buffers]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Procs procs(device);
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Geometries(1));
  commands.End(build);
  REQUIRE(commands.Submit(build) == VK_SUCCESS);
  VkCommandBuffer secondary = BeginSimultaneous(device, commands, VK_COMMAND_BUFFER_LEVEL_SECONDARY);
  commands.Barrier(secondary);
  blas.Update(secondary, Geometries(1));
  commands.Barrier(secondary);
  blas.Build(secondary, Geometries(2));
  commands.End(secondary);

  SECTION("executed twice") {
    VkCommandBuffer primary = commands.Begin();
    const VkCommandBuffer twice[2] = {secondary, secondary};
    procs.CmdExecuteCommands(primary, 2, twice);
    commands.End(primary);
    f.monitor().Expect(k03758);
    CHECK(commands.Submit(primary) == VK_ERROR_VALIDATION_FAILED_EXT);
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].id_name == k03758);
    CHECK(Contains(messages[0].text, "a secondary executed by VkCommandBuffer"));
    CHECK(Contains(messages[0].text, "geometryCount is 1"));
    CHECK(Contains(messages[0].text, "with geometryCount 2"));
  }
  SECTION("valid twin: executed once, then a 1-geometry build, then again") {
    VkCommandBuffer restore = BeginSimultaneous(device, commands, VK_COMMAND_BUFFER_LEVEL_SECONDARY);
    commands.Barrier(restore);
    blas.Build(restore, Geometries(1));
    commands.End(restore);
    VkCommandBuffer primary = commands.Begin();
    const VkCommandBuffer sequence[3] = {secondary, restore, secondary};
    procs.CmdExecuteCommands(primary, 3, sequence);
    commands.End(primary);
    CHECK(commands.Submit(primary) == VK_SUCCESS);
    CHECK(f.monitor().Verify() == "");
  }
}

// ---- a secondary re-recorded between two submissions of a primary that executes it -----------------------------

// The secondary builds A with 1 geometry and the primary executing it is submitted; then the secondary is
// re-recorded to build A with 2 geometries, the primary (now invalid) is recorded again and submitted.
struct RerecordedSecondary {
  explicit RerecordedSecondary(HistoryFixture& f)
      : device(f.device()), procs(device), inputs(device), blas(device, inputs), commands(device) {
    secondary = commands.BeginSecondary();
    blas.Build(secondary, Geometries(1));
    commands.End(secondary);
    primary = commands.Begin();
    procs.CmdExecuteCommands(primary, 1, &secondary);
    commands.End(primary);
    REQUIRE(commands.Submit(primary) == VK_SUCCESS);
  }
  // `reset`: vkResetCommandBuffer first; otherwise vkBeginCommandBuffer resets implicitly.
  void Rerecord(bool reset) {
    if (reset) REQUIRE(vkResetCommandBuffer(secondary, 0) == VK_SUCCESS);
    BeginRecording(secondary, VK_COMMAND_BUFFER_LEVEL_SECONDARY, 0);
    blas.Build(secondary, Geometries(2));
    commands.End(secondary);
    if (reset) REQUIRE(vkResetCommandBuffer(primary, 0) == VK_SUCCESS);
    BeginRecording(primary, VK_COMMAND_BUFFER_LEVEL_PRIMARY, 0);
    procs.CmdExecuteCommands(primary, 1, &secondary);
    commands.End(primary);
    REQUIRE(commands.Submit(primary) == VK_SUCCESS);
  }
  VkCommandBuffer RecordUpdate(uint32_t geometries) {
    VkCommandBuffer cb = commands.Begin();
    blas.Update(cb, Geometries(geometries));
    commands.End(cb);
    return cb;
  }

  vkkit::Device& device;
  Procs procs;
  Inputs inputs;
  Blas blas;
  Commands commands;
  VkCommandBuffer secondary = VK_NULL_HANDLE;
  VkCommandBuffer primary = VK_NULL_HANDLE;
};

TEST_CASE("history valid twin: a re-recorded secondary, executed by a re-recorded primary, then an update of the new "
          "build, stays silent",
          "[integration][history][command-buffers]") {
  HistoryFixture f;
  RerecordedSecondary s(f);
  bool reset = false;
  SECTION("re-recorded by vkBeginCommandBuffer") { reset = false; }
  SECTION("reset by vkResetCommandBuffer, then recorded") { reset = true; }
  s.Rerecord(reset);
  VkCommandBuffer update = s.RecordUpdate(2);  // matches the new recording only
  CHECK(s.commands.Submit(update) == VK_SUCCESS);
  CHECK(s.commands.Submit(s.primary) == VK_SUCCESS);  // the new recording again, and the update again
  CHECK(s.commands.Submit(update) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: after a secondary is re-recorded, an update matching only its old recording is reported (03758)",
          "[integration][history][command-buffers]") {
  HistoryFixture f("history");
  RerecordedSecondary s(f);
  bool reset = false;
  SECTION("re-recorded by vkBeginCommandBuffer") { reset = false; }
  SECTION("reset by vkResetCommandBuffer, then recorded") { reset = true; }
  s.Rerecord(reset);
  VkCommandBuffer update = s.RecordUpdate(1);  // matches the old recording only
  f.monitor().Expect(k03758);
  CHECK(s.commands.Submit(update) == VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].id_name == k03758);
  CHECK(Contains(messages[0].text, "geometryCount is 1"));
  CHECK(Contains(messages[0].text, "with geometryCount 2"));
}

}  // namespace
}  // namespace asval_test
