// Cases that need what no local driver executes: indirect builds that run, on asval's test driver (tests/driver,
// run_corpus.py places it last over lavapipe and enables the feature). Their rules are judged on the bytes the device
// read: an indirect update's primitives (pInfos-03664) and an indirect top-level build's instances (pInfos-12281),
// each with its valid twin. The host and indirect cases of the other files run there too, as their twins
// ("@test-driver", run_corpus.py).
#include <cstring>
#include <vector>

#include "corpus.h"
#include "indirect_helpers.h"

namespace {

using asval_test::Blas;
using asval_test::Component;
using asval_test::IndirectRig;
using asval_test::IndirectTlas;
using asval_test::kNan;
using asval_test::Shape;
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

CORPUS_CASE_ON_TEST_DRIVER(IndirectTlasDestroyedBlas, "history-indirect-tlas-instance-of-destroyed-blas", "history",
                           kIndirect, "an indirect TLAS build whose range info selects an instance of a destroyed BLAS",
                           {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12281"}) {
  IndirectRig rig(device);
  rig.Build(Triangles());
  Blas gone(device, rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { gone.Build(cb, Shape{}); });
  IndirectTlas top(device);
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &gone});
  gone.DestroyHandle();
  top.Build(instances, 2);
  device.Destroy(instances);
}

CORPUS_CASE_ON_TEST_DRIVER(IndirectTlasReadsRangeCount, "history-indirect-tlas-reads-only-the-range-count", "history",
                           kIndirect,
                           "an indirect TLAS build of one instance (its range info's count) from a buffer whose next "
                           "instance names a destroyed BLAS",
                           {}) {
  IndirectRig rig(device);
  rig.Build(Triangles());
  Blas gone(device, rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { gone.Build(cb, Shape{}); });
  IndirectTlas top(device);
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &gone});
  gone.DestroyHandle();
  top.Build(instances, 1);
  device.Destroy(instances);
}

}  // namespace
