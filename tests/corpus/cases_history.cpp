// Family "history", the rules decided in execution order at submission: an update must repeat its source's LAST
// EXECUTED build (pInfos-03667, 03758..03767, primitiveCount-03769), and copies, serialization and property queries
// need a source that was built (src-04963, src-04959, pAccelerationStructures-04964) with the right flags (src-03411,
// accelerationStructures-03431). Most cases are about the order a record-time validator gets wrong both ways:
// command buffers recorded in one order and submitted in another, resubmitted, executed as secondaries, pending twice.
// Every case records, submits and waits. The invalid update itself is recorded (it reaches the driver's recording);
// the submission that would execute it is what a layer must stop.
#include <algorithm>
#include <memory>

#include "corpus.h"
#include "history_helpers.h"
#include "memory_placement_helpers.h"

namespace {

using asval_test::Blas;
using asval_test::Commands;
using asval_test::Inputs;
using asval_test::Procs;
using asval_test::QueryPool;
using asval_test::Shape;
using asval_test::Tlas;

constexpr VkBuildAccelerationStructureFlagsKHR kUpdatable =
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
constexpr VkBuildAccelerationStructureFlagsKHR kCompactable =
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;

Shape Geometries(uint32_t n, VkBuildAccelerationStructureFlagsKHR flags = kUpdatable) {
  Shape s;
  s.geometries = n;
  s.flags = flags;
  return s;
}

// A primary command buffer of `commands` begun with `flags` (SIMULTANEOUS_USE for one submitted while pending).
VkCommandBuffer BeginWith(vkkit::Device& device, Commands& commands, VkCommandBufferLevel level,
                          VkCommandBufferUsageFlags flags) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = commands.pool();
  alloc.level = level;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateCommandBuffers(device.handle(), &alloc, &cb), "vkAllocateCommandBuffers");
  VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = flags;
  if (level == VK_COMMAND_BUFFER_LEVEL_SECONDARY) begin.pInheritanceInfo = &inheritance;
  vkkit::Check(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  return cb;
}

// Submits `cbs` as one batch without waiting: they stay pending until the next wait.
VkResult SubmitPending(vkkit::Device& device, const std::vector<VkCommandBuffer>& cbs) {
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = static_cast<uint32_t>(cbs.size());
  submit.pCommandBuffers = cbs.data();
  return vkQueueSubmit(device.queue(), 1, &submit, VK_NULL_HANDLE);
}

// A command buffer holding one build (or one update) of `blas`, recorded now and submitted whenever.
VkCommandBuffer RecordBuild(Commands& commands, Blas& blas, const Shape& shape) {
  VkCommandBuffer cb = commands.Begin();
  commands.Barrier(cb);
  blas.Build(cb, shape);
  commands.End(cb);
  return cb;
}
VkCommandBuffer RecordUpdate(Commands& commands, Blas& blas, const Shape& shape, const Blas* src = nullptr) {
  VkCommandBuffer cb = commands.Begin();
  commands.Barrier(cb);
  blas.Update(cb, shape, src);
  commands.End(cb);
  return cb;
}

// ---- execution order ------------------------------------------------------------------------------------------

CORPUS_CASE(UpdateSubmittedBeforeBuild, "history-update-submitted-before-its-build", "history",
            "a refit recorded after the BLAS build but submitted first: at its execution the source was never built",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = RecordBuild(commands, blas, Shape{});
  VkCommandBuffer refit = RecordUpdate(commands, blas, Shape{});
  commands.Submit(refit);
  commands.Submit(build);
}

CORPUS_CASE(UpdateRecordedFirstTwoBatches, "history-update-recorded-first-two-batches", "history",
            "a refit recorded before the BLAS build, both submitted in one vkQueueSubmit as two batches, build first",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer refit = RecordUpdate(commands, blas, Shape{});
  VkCommandBuffer build = RecordBuild(commands, blas, Shape{});
  VkSubmitInfo batches[2] = {{VK_STRUCTURE_TYPE_SUBMIT_INFO}, {VK_STRUCTURE_TYPE_SUBMIT_INFO}};
  batches[0].commandBufferCount = batches[1].commandBufferCount = 1;
  batches[0].pCommandBuffers = &build;
  batches[1].pCommandBuffers = &refit;
  vkkit::Check(vkQueueSubmit(device.queue(), 2, batches, VK_NULL_HANDLE), "vkQueueSubmit");
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
}

CORPUS_CASE(UpdateFirstInOneBatch, "history-update-before-build-in-one-batch", "history",
            "the refit and the BLAS build command buffers submitted in one batch, the refit listed first",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = RecordBuild(commands, blas, Shape{});
  VkCommandBuffer refit = RecordUpdate(commands, blas, Shape{});
  commands.Submit({refit, build});
}

CORPUS_CASE(UpdateAgainstBuildExecutedLast, "history-update-matches-build-recorded-last-not-executed-last", "history",
            "two builds of one BLAS (1 and 2 geometries) recorded in that order, submitted in the other; a 2-geometry "
            "refit then contradicts the 1-geometry build that executed last",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer one = RecordBuild(commands, blas, Geometries(1));
  VkCommandBuffer two = RecordBuild(commands, blas, Geometries(2));
  VkCommandBuffer refit = RecordUpdate(commands, blas, Geometries(2));
  commands.Submit(two);
  commands.Submit(one);
  commands.Submit(refit);
}

CORPUS_CASE(UpdateMatchesBuildExecutedLast, "history-update-matches-build-executed-last", "history",
            "two builds of one BLAS (1 and 2 geometries) recorded in that order, submitted in the other; the refit "
            "repeats the 1-geometry build, which executed last",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer one = RecordBuild(commands, blas, Geometries(1));
  VkCommandBuffer two = RecordBuild(commands, blas, Geometries(2));
  VkCommandBuffer refit = RecordUpdate(commands, blas, Geometries(1));
  commands.Submit(two);
  commands.Submit(one);
  commands.Submit(refit);
}

CORPUS_CASE(ResubmittedRefitAfterRebuild, "history-resubmitted-refit-after-other-rebuild", "history",
            "a refit command buffer recorded once and submitted every frame; after a frame that rebuilds the BLAS with "
            "one geometry fewer, its next submission contradicts that rebuild",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer full = RecordBuild(commands, blas, Geometries(2));
  VkCommandBuffer reduced = RecordBuild(commands, blas, Geometries(1));
  VkCommandBuffer refit = RecordUpdate(commands, blas, Geometries(2));
  commands.Submit(full);
  commands.Submit(refit);
  commands.Submit(refit);
  commands.Submit(reduced);
  commands.Submit(refit);
}

CORPUS_CASE(LodRebuildsResubmitted, "history-lod-rebuilds-and-refits-resubmitted", "history",
            "a BLAS rebuilt with 1 or 2 geometries as its level of detail changes, each level's build and refit "
            "command buffers recorded once and resubmitted in the order the frames need",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build[2] = {RecordBuild(commands, blas, Geometries(1)), RecordBuild(commands, blas, Geometries(2))};
  VkCommandBuffer refit[2] = {RecordUpdate(commands, blas, Geometries(1)),
                              RecordUpdate(commands, blas, Geometries(2))};
  const int lod[] = {1, 1, 0, 0, 0, 1, 0};
  int current = -1;
  for (int level : lod) {
    if (level != current) commands.Submit(build[level]);
    commands.Submit(refit[level]);
    current = level;
  }
}

// ---- secondaries and simultaneous use -------------------------------------------------------------------------

CORPUS_CASE(SecondaryBuildWithoutAllowUpdate, "history-secondary-build-without-allow-update-then-refit", "history",
            "a secondary command buffer builds a BLAS without ALLOW_UPDATE; the primary executing it then refits that "
            "BLAS",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Procs procs(device);
  const Shape fixed = Geometries(1, VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR);
  VkCommandBuffer secondary = commands.BeginSecondary();
  blas.Build(secondary, fixed);
  commands.End(secondary);
  VkCommandBuffer primary = commands.Begin();
  procs.CmdExecuteCommands(primary, 1, &secondary);
  commands.Barrier(primary);
  blas.Update(primary, fixed);
  commands.End(primary);
  commands.Submit(primary);
}

// A simultaneous-use secondary that refits a 1-geometry BLAS, then rebuilds it with 2 geometries.
VkCommandBuffer RefitThenRebuild(vkkit::Device& device, Commands& commands, Blas& blas) {
  VkCommandBuffer secondary = BeginWith(device, commands, VK_COMMAND_BUFFER_LEVEL_SECONDARY,
                                        VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
  commands.Barrier(secondary);
  blas.Update(secondary, Geometries(1));
  commands.Barrier(secondary);
  blas.Build(secondary, Geometries(2));
  commands.End(secondary);
  return secondary;
}

CORPUS_CASE(SecondaryExecutedTwice, "history-secondary-executed-twice-rebuilds-in-between", "history",
            "a simultaneous-use secondary (refit of the 1-geometry BLAS, then a 2-geometry rebuild) executed twice by "
            "one vkCmdExecuteCommands: the second execution's refit contradicts the first execution's rebuild",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Procs procs(device);
  commands.Submit(RecordBuild(commands, blas, Geometries(1)));
  VkCommandBuffer secondary = RefitThenRebuild(device, commands, blas);
  VkCommandBuffer primary = commands.Begin();
  const VkCommandBuffer twice[2] = {secondary, secondary};
  procs.CmdExecuteCommands(primary, 2, twice);
  commands.End(primary);
  commands.Submit(primary);
}

CORPUS_CASE(SecondaryExecutedTwiceRestored, "history-secondary-executed-twice-restored-in-between", "history",
            "the same simultaneous-use secondary executed twice by one primary, with a secondary rebuilding the "
            "1-geometry BLAS between the two executions",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Procs procs(device);
  commands.Submit(RecordBuild(commands, blas, Geometries(1)));
  VkCommandBuffer secondary = RefitThenRebuild(device, commands, blas);
  VkCommandBuffer restore = BeginWith(device, commands, VK_COMMAND_BUFFER_LEVEL_SECONDARY, 0);
  commands.Barrier(restore);
  blas.Build(restore, Geometries(1));
  commands.End(restore);
  VkCommandBuffer primary = commands.Begin();
  const VkCommandBuffer sequence[3] = {secondary, restore, secondary};
  procs.CmdExecuteCommands(primary, 3, sequence);
  commands.End(primary);
  commands.Submit(primary);
}

// A simultaneous-use primary that refits a 1-geometry BLAS, then rebuilds it with 2 geometries.
VkCommandBuffer PrimaryRefitThenRebuild(vkkit::Device& device, Commands& commands, Blas& blas) {
  VkCommandBuffer cb =
      BeginWith(device, commands, VK_COMMAND_BUFFER_LEVEL_PRIMARY, VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
  commands.Barrier(cb);
  blas.Update(cb, Geometries(1));
  commands.Barrier(cb);
  blas.Build(cb, Geometries(2));
  commands.End(cb);
  return cb;
}

CORPUS_CASE(SimultaneousUsePendingTwice, "history-simultaneous-use-second-pending-submission", "history",
            "a simultaneous-use command buffer (refit of the 1-geometry BLAS, then a 2-geometry rebuild) submitted "
            "twice without a wait: the second submission's refit executes after the first's rebuild",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  commands.Submit(RecordBuild(commands, blas, Geometries(1)));
  VkCommandBuffer cb = PrimaryRefitThenRebuild(device, commands, blas);
  SubmitPending(device, {cb});
  SubmitPending(device, {cb});
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
}

CORPUS_CASE(SimultaneousUseRestored, "history-simultaneous-use-restored-between-pending", "history",
            "the same simultaneous-use command buffer submitted twice without a wait, with a 1-geometry rebuild "
            "submitted between the two",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  commands.Submit(RecordBuild(commands, blas, Geometries(1)));
  VkCommandBuffer cb = PrimaryRefitThenRebuild(device, commands, blas);
  VkCommandBuffer restore = RecordBuild(commands, blas, Geometries(1));
  SubmitPending(device, {cb});
  SubmitPending(device, {restore});
  SubmitPending(device, {cb});
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
}

CORPUS_CASE(SimultaneousUseContradicts, "history-simultaneous-use-refit-fewer-primitives", "history",
            "a simultaneous-use refit with 1 primitive per geometry of a BLAS built with 2, submitted twice",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  Shape built;
  built.triangles = 2;
  built.max_vertex = 5;
  Shape fewer = built;  // maxVertex stays 5: only primitiveCount differs
  fewer.triangles = 1;
  commands.Submit(RecordBuild(commands, blas, built));
  VkCommandBuffer refit =
      BeginWith(device, commands, VK_COMMAND_BUFFER_LEVEL_PRIMARY, VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT);
  commands.Barrier(refit);
  blas.Update(refit, fewer);
  commands.End(refit);
  SubmitPending(device, {refit});
  SubmitPending(device, {refit});
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
}

// A secondary that builds the BLAS with `geometries`, (re-)recorded, and the primary executing it (re-)recorded too:
// re-recording a secondary invalidates the primaries it was recorded into.
void RecordSecondaryBuild(vkkit::Device& device, Commands& commands, Blas& blas, VkCommandBuffer secondary,
                          VkCommandBuffer primary, uint32_t geometries) {
  Procs procs(device);
  VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.pInheritanceInfo = &inheritance;
  vkkit::Check(vkBeginCommandBuffer(secondary, &begin), "vkBeginCommandBuffer");
  blas.Build(secondary, Geometries(geometries));
  commands.End(secondary);
  const VkCommandBufferBeginInfo primary_begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkkit::Check(vkBeginCommandBuffer(primary, &primary_begin), "vkBeginCommandBuffer");
  procs.CmdExecuteCommands(primary, 1, &secondary);
  commands.End(primary);
}

// The streaming pattern: a secondary builds the BLAS with 1 geometry; it is re-recorded with 2 (and its primary
// with it) and submitted; the refit follows.
void RerecordedSecondary(vkkit::Device& device, uint32_t refit_geometries) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer secondary = BeginWith(device, commands, VK_COMMAND_BUFFER_LEVEL_SECONDARY, 0);
  commands.End(secondary);
  VkCommandBuffer primary = commands.Begin();
  commands.End(primary);
  RecordSecondaryBuild(device, commands, blas, secondary, primary, 1);
  commands.Submit(primary);
  VkCommandBuffer refit = RecordUpdate(commands, blas, Geometries(refit_geometries));
  RecordSecondaryBuild(device, commands, blas, secondary, primary, 2);
  commands.Submit(primary);
  commands.Submit(refit);
}

CORPUS_CASE(RerecordedSecondaryOldRefit, "history-rerecorded-secondary-refit-of-old-recording", "history",
            "a secondary building the BLAS with 1 geometry is re-recorded with 2 and its primary submitted again; the "
            "refit recorded in between still repeats the 1-geometry build",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"}) {
  RerecordedSecondary(device, 1);
}

CORPUS_CASE(RerecordedSecondaryNewRefit, "history-rerecorded-secondary-refit-of-new-recording", "history",
            "a secondary building the BLAS with 1 geometry is re-recorded with 2 and its primary submitted again; the "
            "refit, recorded before that re-recording, repeats the 2-geometry build",
            {}) {
  RerecordedSecondary(device, 2);
}

CORPUS_CASE(ResetCommandBufferForgets, "history-reset-command-buffer-rerecorded", "history",
            "a frame's command buffer that built the BLAS with 1 geometry is reset and re-recorded with a 2-geometry "
            "build; after it runs, a 2-geometry refit",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer frame = RecordBuild(commands, blas, Geometries(1));
  commands.Submit(frame);
  vkkit::Check(vkResetCommandBuffer(frame, 0), "vkResetCommandBuffer");
  const VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkkit::Check(vkBeginCommandBuffer(frame, &begin), "vkBeginCommandBuffer");
  commands.Barrier(frame);
  blas.Build(frame, Geometries(2));
  commands.End(frame);
  commands.Submit(frame);
  commands.Submit(RecordUpdate(commands, blas, Geometries(2)));
}

CORPUS_CASE(RefitIntoOtherStructure, "history-refit-into-another-structure", "history",
            "a 2-geometry BLAS refitted into a second structure (srcAccelerationStructure != dst), which is then "
            "refitted in place every frame",
            {}) {
  Inputs inputs(device);
  Blas source(device, inputs), target(device, inputs);
  Commands commands(device);
  commands.Submit(RecordBuild(commands, source, Geometries(2)));
  commands.Submit(RecordUpdate(commands, target, Geometries(2), &source));
  VkCommandBuffer refit = RecordUpdate(commands, target, Geometries(2));
  for (int frame = 0; frame < 3; ++frame) commands.Submit(refit);
}

CORPUS_CASE(RefitIntoOtherStructureSourceRebuilt, "history-refit-into-another-structure-source-rebuilt", "history",
            "a refit from BLAS a into BLAS b, recorded when a had 2 geometries, submitted after a was rebuilt with 1",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"}) {
  Inputs inputs(device);
  Blas source(device, inputs), target(device, inputs);
  Commands commands(device);
  commands.Submit(RecordBuild(commands, source, Geometries(2)));
  VkCommandBuffer refit = RecordUpdate(commands, target, Geometries(2), &source);
  commands.Submit(RecordBuild(commands, source, Geometries(1)));
  commands.Submit(refit);
}

CORPUS_CASE(RecreatedStructureCloned, "history-recreated-structure-cloned-before-build", "history",
            "a BLAS built, destroyed and created again in the same buffer (same address), then cloned before the new "
            "structure is built",
            {"VUID-VkCopyAccelerationStructureInfoKHR-src-04963"}) {
  Inputs inputs(device);
  Blas blas(device, inputs), copy(device, inputs);
  Commands commands(device);
  commands.Submit(RecordBuild(commands, blas, Shape{}));
  blas.Recreate();
  VkCommandBuffer clone = commands.Begin();
  asval_test::CmdCopy(device, clone, blas.handle(), copy.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  commands.End(clone);
  commands.Submit(clone);
}

// ---- what an update must repeat, one rule each -----------------------------------------------------------------

// The BLAS built with `build`, then refitted with `update` in a later frame (device), or on the host.
void RefitMismatch(vkkit::Device& device, const Shape& build, const Shape& update, bool host) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  commands.Submit(RecordBuild(commands, blas, build));
  if (host) {
    blas.HostUpdate(update);
  } else {
    commands.Submit(RecordUpdate(commands, blas, update));
  }
}

Shape FastBuild() {
  Shape s;
  s.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  return s;
}
Shape NotUpdatable() { return Geometries(1, VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR); }
Shape Aabbs() {
  Shape s;
  s.geometry_type = VK_GEOMETRY_TYPE_AABBS_KHR;
  return s;
}
Shape NoDuplicateAnyHit() {
  Shape s;
  s.geometry_flags = VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR;
  return s;
}
Shape TwoComponentVertices() {
  Shape s;
  s.vertex_format = VK_FORMAT_R32G32_SFLOAT;
  return s;
}
Shape MaxVertex(uint32_t max_vertex) {
  Shape s;
  s.max_vertex = max_vertex;
  return s;
}
Shape Indexed() {
  Shape s;
  s.index_type = VK_INDEX_TYPE_UINT32;
  return s;
}
Shape Transformed() {
  Shape s;
  s.transform = true;
  return s;
}
Shape TwoTriangles() {
  Shape s;
  s.triangles = 2;
  s.max_vertex = 5;
  return s;
}

CORPUS_CASE(RefitFlagsDiffer, "history-refit-prefer-fast-build-flags-differ", "history",
            "a BLAS built with ALLOW_UPDATE|PREFER_FAST_TRACE, refitted with ALLOW_UPDATE|PREFER_FAST_BUILD",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03759"}) {
  RefitMismatch(device, Shape{}, FastBuild(), false);
}

CORPUS_CASE(RefitWithoutAllowUpdate, "history-refit-of-build-without-allow-update", "history",
            "a BLAS built without ALLOW_UPDATE, refitted in a later frame",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03667"}) {
  RefitMismatch(device, NotUpdatable(), NotUpdatable(), false);
}

CORPUS_CASE(RefitGeometryTypeDiffers, "history-refit-aabbs-of-triangle-build", "history",
            "a triangle BLAS refitted with an AABB geometry", {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03761"}) {
  RefitMismatch(device, Shape{}, Aabbs(), false);
}

CORPUS_CASE(RefitGeometryFlagsDiffer, "history-refit-geometry-flags-differ", "history",
            "an opaque triangle geometry refitted with NO_DUPLICATE_ANY_HIT instead",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03762"}) {
  RefitMismatch(device, Shape{}, NoDuplicateAnyHit(), false);
}

CORPUS_CASE(RefitVertexFormatDiffers, "history-refit-vertex-format-differs", "history",
            "an R32G32B32_SFLOAT triangle BLAS refitted with R32G32_SFLOAT vertices",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03763"}) {
  RefitMismatch(device, Shape{}, TwoComponentVertices(), false);
}

CORPUS_CASE(RefitMaxVertexDiffers, "history-refit-max-vertex-differs", "history",
            "a triangle BLAS built with maxVertex 2, refitted with maxVertex 5",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03764"}) {
  RefitMismatch(device, Shape{}, MaxVertex(5), false);
}

CORPUS_CASE(RefitIndexTypeDiffers, "history-refit-indexed-of-non-indexed-build", "history",
            "a non-indexed triangle BLAS refitted with UINT32 indices",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03765"}) {
  RefitMismatch(device, Shape{}, Indexed(), false);
}

CORPUS_CASE(RefitAddsTransform, "history-refit-adds-transform", "history",
            "a triangle BLAS built without a transform, refitted with transformData set",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03766"}) {
  RefitMismatch(device, Shape{}, Transformed(), false);
}

CORPUS_CASE(RefitDropsTransform, "history-refit-drops-transform", "history",
            "a triangle BLAS built with a transform, refitted with transformData NULL",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03767"}) {
  RefitMismatch(device, Transformed(), Shape{}, false);
}

CORPUS_CASE(RefitPrimitiveCountDiffers, "history-refit-more-primitives", "history",
            "a 1-triangle BLAS (maxVertex 5) refitted with 2 triangles",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-primitiveCount-03769"}) {
  RefitMismatch(device, MaxVertex(5), TwoTriangles(), false);
}

// A structure created GENERIC may be built as either level; its update must still be of the level it was built
// as (03760), and an instance geometry is then never the triangle geometry it was built with (03761).
// The GENERIC structure built on the device as a bottom-level structure, then updated as a top-level one on the
// device or (`host`) by vkBuildAccelerationStructuresKHR.
void GenericRefitAsOtherLevel(vkkit::Device& device, bool host) {
  Inputs inputs(device);
  Blas referenced(device, inputs);
  asval_test::BuildInfo bottom = asval_test::MakeBuildInfo(Shape{}, inputs);
  Tlas tlas_shape(device, 1);
  vkkit::Buffer instances = tlas_shape.MakeInstances({&referenced});
  asval_test::BuildInfo top = tlas_shape.Info(instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  top.info.flags = bottom.info.flags;  // the flags are repeated: only the level and the geometry type change
  top.info.pGeometries = top.geometries.data();
  const VkAccelerationStructureBuildSizesInfoKHR bottom_sizes = asval_test::DriverSizes(device, bottom.info, {1});
  const VkAccelerationStructureBuildSizesInfoKHR top_sizes = asval_test::DriverSizes(device, top.info, {1});
  vkkit::AccelerationStructure generic = device.CreateAccelerationStructure(
      VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR,
      asval_test::RoundUp(std::max(bottom_sizes.accelerationStructureSize, top_sizes.accelerationStructureSize), 256));
  vkkit::Buffer scratch = device.CreateBuffer(
      std::max({bottom_sizes.buildScratchSize, top_sizes.buildScratchSize, top_sizes.updateScratchSize}),
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  bottom.info.dstAccelerationStructure = generic.handle;
  bottom.info.scratchData.deviceAddress = scratch.address;
  top.info.srcAccelerationStructure = top.info.dstAccelerationStructure = generic.handle;
  top.info.scratchData.deviceAddress = scratch.address;
  Procs procs(device);
  device.OneShot([&](VkCommandBuffer cb) {
    referenced.Build(cb, Shape{});
    procs.CmdBuild(cb, 1, &bottom.info, &bottom.range_pointer);
  });
  if (host) {
    top.info.scratchData.hostAddress = scratch.mapped;
    top.geometries[0].geometry.instances.data.hostAddress = instances.mapped;
    // A host build's instances name structures by handle, not by device address.
    static_cast<VkAccelerationStructureInstanceKHR*>(instances.mapped)->accelerationStructureReference =
        reinterpret_cast<uint64_t>(referenced.handle());
    procs.HostBuild(device.handle(), VK_NULL_HANDLE, 1, &top.info, &top.range_pointer);
  } else {
    Commands commands(device);
    VkCommandBuffer update = commands.Begin();
    procs.CmdBuild(update, 1, &top.info, &top.range_pointer);
    commands.End(update);
    commands.Submit(update);
  }
  device.Destroy(scratch);
  device.Destroy(generic);
  device.Destroy(instances);
}

CORPUS_CASE(RefitGenericAsOtherLevel, "history-generic-structure-refit-as-other-level", "history",
            "a GENERIC structure built as a bottom-level structure of one triangle, then updated as a top-level "
            "structure of one instance",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03760",
             "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03761"}) {
  GenericRefitAsOtherLevel(device, false);
}

// Host refits: lavapipe has no host commands, so these calls are also made on a device without
// accelerationStructureHostCommands, which is a fault of its own (03581) that each of them also carries; a layer
// that stops the call keeps it from the driver.
constexpr const char* kHostCommands = "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581";
CORPUS_CASE(HostRefitGenericAsOtherLevel, "history-host-generic-structure-refit-as-other-level", "history",
            "a GENERIC structure built on the device as a bottom-level structure of one triangle, then updated on the "
            "host as a top-level structure of one instance",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03760",
             "VUID-vkBuildAccelerationStructuresKHR-pInfos-03761"}) {
  GenericRefitAsOtherLevel(device, true);
}

CORPUS_CASE(HostRefitWithoutAllowUpdate, "history-host-refit-of-build-without-allow-update", "history",
            "a BLAS built on the device without ALLOW_UPDATE, refitted by vkBuildAccelerationStructuresKHR",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03667"}) {
  RefitMismatch(device, NotUpdatable(), NotUpdatable(), true);
}

CORPUS_CASE(HostRefitGeometryCount, "history-host-refit-geometry-count-differs", "history",
            "a 1-geometry BLAS refitted on the host with 3 geometries",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03758"}) {
  RefitMismatch(device, Shape{}, Geometries(3), true);
}

CORPUS_CASE(HostRefitFlags, "history-host-refit-flags-differ", "history",
            "a BLAS built PREFER_FAST_TRACE, refitted on the host PREFER_FAST_BUILD",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03759"}) {
  RefitMismatch(device, Shape{}, FastBuild(), true);
}

CORPUS_CASE(HostRefitGeometryType, "history-host-refit-aabbs-of-triangle-build", "history",
            "a triangle BLAS refitted on the host with an AABB geometry",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03761"}) {
  RefitMismatch(device, Shape{}, Aabbs(), true);
}

CORPUS_CASE(HostRefitGeometryFlags, "history-host-refit-geometry-flags-differ", "history",
            "an opaque geometry refitted on the host with NO_DUPLICATE_ANY_HIT",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03762"}) {
  RefitMismatch(device, Shape{}, NoDuplicateAnyHit(), true);
}

CORPUS_CASE(HostRefitVertexFormat, "history-host-refit-vertex-format-differs", "history",
            "an R32G32B32_SFLOAT BLAS refitted on the host with R32G32_SFLOAT vertices",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03763"}) {
  RefitMismatch(device, Shape{}, TwoComponentVertices(), true);
}

CORPUS_CASE(HostRefitMaxVertex, "history-host-refit-max-vertex-differs", "history",
            "a BLAS built with maxVertex 2, refitted on the host with maxVertex 5",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03764"}) {
  RefitMismatch(device, Shape{}, MaxVertex(5), true);
}

CORPUS_CASE(HostRefitIndexType, "history-host-refit-indexed-of-non-indexed-build", "history",
            "a non-indexed BLAS refitted on the host with UINT32 indices",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03765"}) {
  RefitMismatch(device, Shape{}, Indexed(), true);
}

CORPUS_CASE(HostRefitAddsTransform, "history-host-refit-adds-transform", "history",
            "a BLAS built without a transform, refitted on the host with one",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03766"}) {
  RefitMismatch(device, Shape{}, Transformed(), true);
}

CORPUS_CASE(HostRefitDropsTransform, "history-host-refit-drops-transform", "history",
            "a BLAS built with a transform, refitted on the host without",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-pInfos-03767"}) {
  RefitMismatch(device, Transformed(), Shape{}, true);
}

CORPUS_CASE(HostRefitPrimitiveCount, "history-host-refit-more-primitives", "history",
            "a 1-triangle BLAS (maxVertex 5) refitted on the host with 2 triangles",
            {kHostCommands, "VUID-vkBuildAccelerationStructuresKHR-primitiveCount-03769"}) {
  RefitMismatch(device, MaxVertex(5), TwoTriangles(), true);
}

// ---- copies, serialization, property queries ------------------------------------------------------------------

CORPUS_CASE(CompactedCopyRefitOtherCount, "history-compacted-copy-refit-other-geometry-count", "history",
            "a 1-geometry BLAS compacted into a new structure (originals destroyed); the copy is refitted as if it "
            "had 2 geometries",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"}) {
  Inputs inputs(device);
  auto original = std::make_unique<Blas>(device, inputs);
  Blas compact(device, inputs);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  device.OneShot([&](VkCommandBuffer cb) {
    pool.Reset(cb);
    original->Build(cb, Geometries(1, kCompactable));
    Commands(device).Barrier(cb);
    asval_test::CmdWriteProperties(device, cb, {original->handle()},
                                   VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool.handle(), 0);
  });
  pool.Results();
  device.OneShot([&](VkCommandBuffer cb) {
    asval_test::CmdCopy(device, cb, original->handle(), compact.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  });
  original.reset();
  Commands commands(device);
  commands.Submit(RecordUpdate(commands, compact, Geometries(2, kCompactable)));
}

CORPUS_CASE(CompactedCopyRefit, "history-compacted-copy-refit", "history",
            "a 2-geometry BLAS built with ALLOW_UPDATE|ALLOW_COMPACTION, compacted (original destroyed), the copy "
            "refitted every frame with the original's parameters",
            {}) {
  Inputs inputs(device);
  auto original = std::make_unique<Blas>(device, inputs);
  Blas compact(device, inputs);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  device.OneShot([&](VkCommandBuffer cb) {
    pool.Reset(cb);
    original->Build(cb, Geometries(2, kCompactable));
    Commands(device).Barrier(cb);
    asval_test::CmdWriteProperties(device, cb, {original->handle()},
                                   VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool.handle(), 0);
  });
  pool.Results();
  device.OneShot([&](VkCommandBuffer cb) {
    asval_test::CmdCopy(device, cb, original->handle(), compact.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  });
  original.reset();
  Commands commands(device);
  VkCommandBuffer refit = RecordUpdate(commands, compact, Geometries(2, kCompactable));
  for (int frame = 0; frame < 3; ++frame) commands.Submit(refit);
}

CORPUS_CASE(CloneSubmittedBeforeBuild, "history-clone-submitted-before-source-build", "history",
            "a clone of a BLAS recorded after the BLAS build, submitted before it",
            {"VUID-VkCopyAccelerationStructureInfoKHR-src-04963"}) {
  Inputs inputs(device);
  Blas src(device, inputs), dst(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = RecordBuild(commands, src, Shape{});
  VkCommandBuffer clone = commands.Begin();
  commands.Barrier(clone);
  asval_test::CmdCopy(device, clone, src.handle(), dst.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  commands.End(clone);
  commands.Submit(clone);
  commands.Submit(build);
}

CORPUS_CASE(CloneRecordedBeforeBuild, "history-clone-recorded-before-source-build", "history",
            "a clone recorded before the BLAS build it copies, submitted after it, then a clone of the clone", {}) {
  Inputs inputs(device);
  Blas src(device, inputs), dst(device, inputs), dst2(device, inputs);
  Commands commands(device);
  VkCommandBuffer clone = commands.Begin();
  commands.Barrier(clone);
  asval_test::CmdCopy(device, clone, src.handle(), dst.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  commands.Barrier(clone);
  asval_test::CmdCopy(device, clone, dst.handle(), dst2.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  commands.End(clone);
  VkCommandBuffer build = RecordBuild(commands, src, Shape{});
  commands.Submit({build, clone});
}

// The compaction flow's first half: the BLAS built with ALLOW_COMPACTION, its compacted size read back.
void BuildCompactableAndQuery(vkkit::Device& device, Blas& blas) {
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  device.OneShot([&](VkCommandBuffer cb) {
    pool.Reset(cb);
    blas.Build(cb, Geometries(1, kCompactable));
    Commands(device).Barrier(cb);
    asval_test::CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                                   pool.handle(), 0);
  });
  pool.Results();
}

CORPUS_CASE(CompactAfterRebuildWithoutFlag, "history-compact-after-rebuild-without-allow-compaction", "history",
            "a BLAS built with ALLOW_COMPACTION and its size queried; a later frame rebuilds it without the flag; the "
            "compacting copy recorded earlier is submitted after that rebuild",
            {"VUID-VkCopyAccelerationStructureInfoKHR-src-03411"}) {
  Inputs inputs(device);
  Blas blas(device, inputs), compact(device, inputs);
  Commands commands(device);
  BuildCompactableAndQuery(device, blas);
  VkCommandBuffer copy = commands.Begin();
  asval_test::CmdCopy(device, copy, blas.handle(), compact.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  commands.End(copy);
  commands.Submit(RecordBuild(commands, blas, Geometries(1)));  // ALLOW_UPDATE only
  commands.Submit(copy);
}

CORPUS_CASE(SerializeSubmittedBeforeBuild, "history-serialize-submitted-before-build", "history",
            "a BLAS serialized to a buffer by a command buffer recorded after its build, submitted before it",
            {"VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-04959"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  VkCommandBuffer build = RecordBuild(commands, blas, Shape{});
  VkCommandBuffer serialize = commands.Begin();
  commands.Barrier(serialize);
  asval_test::CmdSerialize(device, serialize, blas.handle(), bytes.address);
  commands.End(serialize);
  commands.Submit(serialize);
  commands.Submit(build);
  device.Destroy(bytes);
}

CORPUS_CASE(QuerySubmittedBeforeBuild, "history-size-query-submitted-before-build", "history",
            "a serialization-size query of a BLAS in a command buffer submitted before the one that builds it",
            {"VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-04964"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 1);
  VkCommandBuffer build = RecordBuild(commands, blas, Shape{});
  VkCommandBuffer query = commands.Begin();
  pool.Reset(query);
  commands.Barrier(query);
  asval_test::CmdWriteProperties(device, query, {blas.handle()},
                                 VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, pool.handle(), 0);
  commands.End(query);
  commands.Submit(query);
  commands.Submit(build);
}

CORPUS_CASE(CompactedSizeAfterRebuild, "history-compacted-size-query-after-rebuild-without-flag", "history",
            "a compacted-size query recorded after a build with ALLOW_COMPACTION, submitted after a rebuild without it",
            {"VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-accelerationStructures-03431"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  VkCommandBuffer compactable = RecordBuild(commands, blas, Geometries(1, kCompactable));
  VkCommandBuffer query = commands.Begin();
  pool.Reset(query);
  commands.Barrier(query);
  asval_test::CmdWriteProperties(device, query, {blas.handle()},
                                 VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool.handle(), 0);
  commands.End(query);
  commands.Submit(compactable);
  commands.Submit(RecordBuild(commands, blas, Geometries(1)));  // rebuilt without ALLOW_COMPACTION
  commands.Submit(query);
}

CORPUS_CASE(CompactedSizeAfterRebuildWithFlag, "history-compacted-size-query-recorded-before-build", "history",
            "a compacted-size query recorded before any build, submitted after a rebuild with ALLOW_COMPACTION that "
            "followed a build without it",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  VkCommandBuffer query = commands.Begin();
  pool.Reset(query);
  commands.Barrier(query);
  asval_test::CmdWriteProperties(device, query, {blas.handle()},
                                 VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool.handle(), 0);
  commands.End(query);
  commands.Submit(RecordBuild(commands, blas, Geometries(1)));
  commands.Submit(RecordBuild(commands, blas, Geometries(1, kCompactable)));
  commands.Submit(query);
  pool.Results();
}

}  // namespace
