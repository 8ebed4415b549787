// Cases that need what no local driver executes: indirect builds that run, on asval's test driver (tests/driver,
// run_corpus.py places it last over lavapipe and enables the feature). Their rules are judged on the bytes the device
// read: an indirect update's primitives (pInfos-03664) and an indirect top-level build's instances (pInfos-12281),
// each with its valid twin. The host and indirect cases of the other files run there too, as their twins
// ("@test-driver", run_corpus.py).
#include <cstring>
#include <vector>

#include "corpus.h"
#include "indirect_helpers.h"
#include "on_test_driver.h"
#include "ray_program.h"

namespace {

using asval_test::Component;
using asval_test::IndirectRig;
using asval_test::kNan;
using asval_test::TopLevelRig;
using asval_test::Triangles;
using asval_test::Vertices;

constexpr const char* kIndirect = "indirect-build";

// An indirect update of the rig's structure in place, its vertices moved by dx on the device first, and a NaN X over
// vertex 0 when asked (triangle 0 then inactive).
void IndirectUpdate(IndirectRig& rig, bool nan_over_vertex_0, float dx) {
  rig.SetRanges({IndirectRig::ShapeRange(Triangles())});
  rig.Run([&](VkCommandBuffer cb) {
    rig.Write(cb, Component(0, 0), Vertices(dx));
    if (nan_over_vertex_0) rig.Fill(cb, Component(0, 0), kNan);
    rig.Record(cb, Triangles(), VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
}

CORPUS_CASE_ON_TEST_DRIVER(IndirectRefitDeactivates, "history-indirect-refit-deactivates-triangle", "history",
                           kIndirect,
                           "an indirect refit whose vertices, written on the device before it, make a triangle of "
                           "its source inactive",
                           {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03664"}) {
  IndirectRig rig(device);
  rig.Build(Triangles());
  IndirectUpdate(rig, true, 0.5f);
}

CORPUS_CASE_ON_TEST_DRIVER(IndirectRefitKeepsActivity, "history-indirect-refit-keeps-activity", "history", kIndirect,
                           "indirect refits of a structure built indirectly, its vertices moved on the device each "
                           "time",
                           {}) {
  IndirectRig rig(device);
  rig.Build(Triangles());
  for (float dx : {0.25f, 0.5f, 0.75f}) IndirectUpdate(rig, false, dx);
}

// An indirect TLAS build over instances of a live BLAS and of one whose handle was destroyed, `count` of them read
// (the range info's count; the recorded maximum is 4).
void BuildOverDestroyedBlas(vkkit::Device& device, uint32_t count) {
  TopLevelRig made(device);
  auto& [rig, gone, top] = made;
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &gone});
  gone.DestroyHandle();
  top.Build(instances, count);
  device.Destroy(instances);
}

CORPUS_CASE_ON_TEST_DRIVER(IndirectTlasDestroyedBlas, "history-indirect-tlas-instance-of-destroyed-blas", "history",
                           kIndirect, "an indirect TLAS build whose range info selects an instance of a destroyed BLAS",
                           {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12281"}) {
  BuildOverDestroyedBlas(device, 2);
}

CORPUS_CASE_ON_TEST_DRIVER(IndirectTlasReadsRangeCount, "history-indirect-tlas-reads-only-the-range-count", "history",
                           kIndirect,
                           "an indirect TLAS build of one instance (its range info's count) from a buffer whose next "
                           "instance names a destroyed BLAS",
                           {}) {
  BuildOverDestroyedBlas(device, 1);
}

// Ray-query frames over a top level of one bottom level, the frame's dispatch held pending on the test driver (a busy
// GPU: the layers above see a submission with no wait, not yet complete) while the host streams a bottom level out.
class HeldFrames {
 public:
  explicit HeldFrames(vkkit::Device& device)
      : device_(device),
        held_(device),
        commands_(device),
        scene_(device),
        program_(device, asval_test::RayProgram::Kind::kRayQuery) {
    held_.SubmitAndWait(Recorded([&](VkCommandBuffer cb) { scene_.Build(commands_, cb); }));
    program_.Write(scene_.tlas.handle());
  }
  // The top level rebuilt over `blas` alone, waited for.
  void RebuildOver(asval_test::Blas& blas) {
    vkkit::Buffer instances = scene_.tlas.MakeInstances({&blas});
    held_.SubmitAndWait(Recorded([&](VkCommandBuffer cb) {
      blas.Build(cb, asval_test::Shape{});
      commands_.Barrier(cb);
      scene_.tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    }));
    device_.Destroy(instances);
  }
  // One frame's dispatch, held pending while `meanwhile` runs on the host, then released and waited for.
  template <typename F>
  void FrameWhile(F&& meanwhile) {
    held_.SubmitHeld(Recorded([&](VkCommandBuffer cb) { program_.Record(cb); }));  // may be kept back: not checked
    meanwhile();
    vkkit::Check(held_.Release(), "vkAsvalTestDriverHoldSubmissions");
  }
  asval_test::RayScene& scene() { return scene_; }

 private:
  template <typename F>
  VkCommandBuffer Recorded(F&& record) {
    const VkCommandBuffer cb = commands_.Begin();
    record(cb);
    commands_.End(cb);
    return cb;
  }

  vkkit::Device& device_;
  asval_test::HeldSubmissions held_;
  asval_test::Commands commands_;
  asval_test::RayScene scene_;
  asval_test::RayProgram program_;
};

constexpr const char* kHeld = "held-submissions";

CORPUS_CASE_ON_TEST_DRIVER(TracesBottomLevelDestroyedWhilePending, "traces-bottom-level-destroyed-while-query-pending",
                           "traces", kHeld,
                           "a bottom-level structure streamed out (its handle destroyed, its memory kept) while the "
                           "frame's ray-query dispatch over the top level referencing it is still executing",
                           {"ASVAL-Traces-BottomLevelInvalid"}) {
  HeldFrames frames(device);
  frames.FrameWhile([&] { frames.scene().blas.DestroyHandle(); });
}

CORPUS_CASE_ON_TEST_DRIVER(TracesBottomLevelStreamedOutSafely,
                           "traces-bottom-level-streamed-out-while-next-frame-pending", "traces", kHeld,
                           "streaming: the top level is rebuilt over a new bottom level and waited for, then the next "
                           "frame's ray-query dispatch is still executing while the old bottom level is destroyed",
                           {}) {
  HeldFrames frames(device);
  asval_test::Blas replacement(device, frames.scene().inputs);
  frames.FrameWhile([] {});
  frames.RebuildOver(replacement);
  frames.FrameWhile([&] { frames.scene().blas.DestroyHandle(); });
}

}  // namespace
