// Family traces (issue 29): ray-query work over top-level structures, as engines record it (the structure rebuilt
// every frame and queried after a barrier in the same command buffer; built once in its own submission and queried
// by later ones; bottom levels streamed in and out, or rebuilt with another layout, under a TLAS rebuilt after
// them), and the faults: a dispatch whose descriptor names a top-level structure no build executed on, and a top
// level traced after a bottom level it references was destroyed.
#include <cstring>
#include <memory>

#include "corpus.h"
#include "ray_program.h"

namespace corpus {
namespace {

using asval_test::Commands;
using asval_test::RayProgram;
using asval_test::RayScene;

}  // namespace

CORPUS_CASE(TracesRebuiltEachFrame, "traces-ray-query-after-tlas-rebuild-each-frame", "patterns",
            "the TLAS rebuilt every frame from a new instance buffer, a barrier, then a ray-query dispatch reading "
            "it through a descriptor set, in one command buffer per frame",
            {}) {
  RayScene scene(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Commands commands(device);
  device.OneShot([&](VkCommandBuffer cb) { scene.blas.Build(cb, asval_test::Shape{}); });
  for (int frame = 0; frame < 4; ++frame) {
    vkkit::Buffer instances = scene.tlas.MakeInstances({&scene.blas});
    VkCommandBuffer cb = commands.Begin();
    scene.tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    program.BarrierAfterBuild(cb);
    program.Record(cb);
    commands.End(cb);
    vkkit::Check(commands.Submit(cb), "vkQueueSubmit");  // waits for the queue
    device.Destroy(instances);
  }
}

CORPUS_CASE(TracesBuiltOnceQueriedLater, "traces-ray-query-in-later-submissions", "patterns",
            "a static scene: both structures built once in a one-shot submission, then ray-query dispatches in "
            "later submissions, the descriptor written before the build",
            {}) {
  RayScene scene(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());  // engines write descriptors at load time, before the first build
  Commands commands(device);
  vkkit::Check(commands.Submit([&] {
    VkCommandBuffer cb = commands.Begin();
    scene.Build(commands, cb);
    commands.End(cb);
    return cb;
  }()),
               "vkQueueSubmit");
  for (int frame = 0; frame < 3; ++frame) {
    VkCommandBuffer cb = commands.Begin();
    program.Record(cb);
    commands.End(cb);
    vkkit::Check(commands.Submit(cb), "vkQueueSubmit");
  }
}

CORPUS_CASE(TracesBottomLevelsStreamed, "traces-bottom-levels-streamed-under-tlas-rebuilt-each-frame", "patterns",
            "bottom levels streamed in and out: each frame builds a new bottom level, rebuilds the TLAS over it, and "
            "queries; after the frame's fence wait the previous frame's bottom level is destroyed (with its memory)",
            {}) {
  RayScene scene(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Commands commands(device);
  std::unique_ptr<asval_test::Blas> previous;
  for (int frame = 0; frame < 4; ++frame) {
    auto streamed = std::make_unique<asval_test::Blas>(device, scene.inputs);
    vkkit::Buffer instances = scene.tlas.MakeInstances({streamed.get()});
    VkCommandBuffer cb = commands.Begin();
    streamed->Build(cb, asval_test::Shape{});
    commands.Barrier(cb);
    scene.tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    program.BarrierAfterBuild(cb);
    program.Record(cb);
    commands.End(cb);
    vkkit::Check(commands.Submit(cb), "vkQueueSubmit");  // waits for the queue
    device.Destroy(instances);
    previous = std::move(streamed);  // the one before is destroyed here: the TLAS no longer references it
  }
}

CORPUS_CASE(TracesBottomLevelRelaidOut, "traces-bottom-level-rebuilt-with-more-geometries-then-tlas", "patterns",
            "a bottom level rebuilt with a second geometry (an object gaining a part), the TLAS rebuilt after it in "
            "the same command buffer, then queried in later frames",
            {}) {
  RayScene scene(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Commands commands(device);
  asval_test::Shape two;
  two.geometries = 2;
  for (int frame = 0; frame < 3; ++frame) {
    VkCommandBuffer cb = commands.Begin();
    if (frame == 0) scene.Build(commands, cb);
    if (frame == 1) {
      scene.blas.Build(cb, two);
      commands.Barrier(cb);
      scene.tlas.Record(cb, scene.instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    }
    program.BarrierAfterBuild(cb);
    program.Record(cb);
    commands.End(cb);
    vkkit::Check(commands.Submit(cb), "vkQueueSubmit");
  }
}

CORPUS_CASE(TracesNeverBuilt, "traces-ray-query-over-unbuilt-tlas", "traces",
            "a ray-query dispatch whose descriptor names a top-level structure created but never built (its "
            "storage zeroed, so a driver that runs it reads an empty structure)",
            {"VUID-RuntimeSpirv-OpRayQueryInitializeKHR-06352"}) {
  vkkit::AccelerationStructure never_built =
      device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, 4096);
  std::memset(never_built.storage.mapped, 0, never_built.storage.size);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(never_built.handle);
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  program.Record(cb);
  commands.End(cb);
  commands.Submit(cb);  // a layer that reports it may keep it from the driver
  device.Destroy(never_built);
}

CORPUS_CASE(TracesBottomLevelDestroyed, "traces-bottom-level-destroyed-under-traced-tlas", "traces",
            "a static scene whose bottom-level structure's handle is destroyed (its memory kept) while the top level "
            "built over it is still traced by later ray-query dispatches, without a rebuild",
            {"ASVAL-Traces-BottomLevelInvalid"}) {
  RayScene scene(device);
  RayProgram program(device, RayProgram::Kind::kRayQuery);
  program.Write(scene.tlas.handle());
  Commands commands(device);
  VkCommandBuffer build = commands.Begin();
  scene.Build(commands, build);
  commands.End(build);
  vkkit::Check(commands.Submit(build), "vkQueueSubmit");
  scene.blas.DestroyHandle();
  VkCommandBuffer cb = commands.Begin();
  program.Record(cb);
  commands.End(cb);
  commands.Submit(cb);  // a layer that reports it may keep it from the driver
}

}  // namespace corpus
