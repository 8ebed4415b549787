// Host builds' activity (vkBuildAccelerationStructuresKHR): the inputs of updatable builds and updates are copied
// when the build is called (host_capture.h), the update rules on primitive activity and index values
// (pInfos-03663, 03664, 03768) judge a host update on them before its downcall, and the history keeps a host
// build's activity for later updates, host or device. Lavapipe has no host commands: the calls are made here,
// without a driver, as the hook makes them (capture, validate, apply).
#include <catch2/catch_test_macros.hpp>

#include <string>
#include <vector>

#include "history_host.h"
#include "history_recorder.h"
#include "history_test_builds.h"
#include "host_capture.h"
#include "record_checks_harness.h"

namespace asval::test {
namespace {

constexpr const char* kBecameActive = "VUID-vkBuildAccelerationStructuresKHR-pInfos-03663";
constexpr const char* kBecameInactive = "VUID-vkBuildAccelerationStructuresKHR-pInfos-03664";
constexpr const char* kIndicesChanged = "VUID-vkBuildAccelerationStructuresKHR-pInfos-03768";
constexpr VkBuildAccelerationStructureFlagsKHR kUpdatable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
constexpr uint32_t kHistoryFamilies = kRecordFamilies | kCheckHistory;
constexpr float kNan = __builtin_nanf("");

// Two triangles of R32G32B32_SFLOAT vertices, 6 vertices (18 floats) in host memory, optionally indexed.
struct HostTriangles {
  std::vector<float> vertices = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 2, 1, 0};
  std::vector<uint32_t> indices = {0, 1, 2, 3, 4, 5};
  Build build;

  HostTriangles(VkAccelerationStructureKHR dst, VkAccelerationStructureKHR update_src = VK_NULL_HANDLE,
                bool indexed = false)
      : build(dst, {2}, kUpdatable, update_src) {
    VkAccelerationStructureGeometryTrianglesDataKHR& t = build.geometries[0].geometry.triangles;
    t.vertexData.hostAddress = vertices.data();
    t.vertexStride = 12;
    t.maxVertex = 5;
    t.indexType = VK_INDEX_TYPE_NONE_KHR;
    if (indexed) {
      t.indexType = VK_INDEX_TYPE_UINT32;
      t.indexData.hostAddress = indices.data();
    }
  }
};

// One host build as the hook runs it: captured, validated (the VUIDs it reports are returned), applied.
std::vector<std::string> HostRun(RecordHarness& h, const Build& b) {
  return h.RunCheck(
      [&](const CheckContext& ctx) {
        HostCapture capture =
            CaptureHostBuildInputs(1, &b.info, &b.range_pointer, VkDeviceSize{1} << 20, ctx.state.capture_counters);
        BuildCommand cmd{BuildCommandKind::kHostBuild, "vkBuildAccelerationStructuresKHR"};
        cmd.info_count = 1;
        cmd.infos = &b.info;
        cmd.ranges = &b.range_pointer;
        cmd.host_capture = capture.log.get();
        cmd.host_captured = capture.captured_or_null();
        if (ValidateBuildHistory(ctx, cmd)) return;  // skipped, as the hook would
        FinishHostOps(h.state(), HostBuildOps(1, &b.info, &b.range_pointer, capture.log.get(), capture.captured_or_null()),
                      VK_NULL_HANDLE, VK_SUCCESS, capture.log);
      },
      kHistoryFamilies);
}

using Ids = std::vector<std::string>;

}  // namespace

TEST_CASE("host capture unit: a host update that makes a triangle inactive or active is reported (pInfos-03664, "
          "03663)",
          "[unit][capture][host]") {
  RecordHarness h;
  const VkAccelerationStructureKHR blas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  HostTriangles built(blas);
  CHECK(HostRun(h, built.build) == Ids{});
  HostTriangles nan_x(blas, blas);
  nan_x.vertices[3 * 4] = kNan;  // X of vertex 4: triangle 1 inactive
  CHECK(HostRun(h, nan_x.build) == Ids{kBecameInactive});
  CHECK(h.texts().back().find("primitive 1") != std::string::npos);
  // The update was skipped (the finding asked for it): the source still has both triangles active. A valid
  // update is silent; then the history holds its activity, and an update that brings the NaN back is reported.
  HostTriangles moved(blas, blas);
  moved.vertices[0] = 0.5f;
  CHECK(HostRun(h, moved.build) == Ids{});
  HostTriangles nan_again(blas, blas);
  nan_again.vertices[0] = kNan;  // triangle 0 inactive
  CHECK(HostRun(h, nan_again.build) == Ids{kBecameInactive});
}

TEST_CASE("host capture unit: a host update with other index values is reported (pInfos-03768)",
          "[unit][capture][host]") {
  RecordHarness h;
  const VkAccelerationStructureKHR blas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  HostTriangles built(blas, VK_NULL_HANDLE, true);
  CHECK(HostRun(h, built.build) == Ids{});
  HostTriangles same(blas, blas, true);
  same.vertices[1] = 0.25f;  // a refit: the same indices
  CHECK(HostRun(h, same.build) == Ids{});
  HostTriangles swapped(blas, blas, true);
  swapped.indices = {0, 2, 1, 3, 4, 5};
  CHECK(HostRun(h, swapped.build) == Ids{kIndicesChanged});
}

TEST_CASE("host capture unit: a host update of a source whose activity is unknown is skipped and counted",
          "[unit][capture][host]") {
  RecordHarness h;
  const VkAccelerationStructureKHR blas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  // Built without its inputs readable (a null vertex pointer with primitives: not captured): activity unknown.
  HostTriangles built(blas);
  built.build.geometries[0].geometry.triangles.vertexData.hostAddress = nullptr;
  HostRun(h, built.build);
  const uint64_t skipped = h.state().checks_skipped_unknown_state.load();
  HostTriangles nan_x(blas, blas);
  nan_x.vertices[0] = kNan;
  CHECK(HostRun(h, nan_x.build) == Ids{});
  CHECK(h.state().checks_skipped_unknown_state.load() == skipped + 1);
}

TEST_CASE("host capture unit: an inactive triangle made active by a host update is reported (pInfos-03663)",
          "[unit][capture][host]") {
  RecordHarness h;
  const VkAccelerationStructureKHR blas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  HostTriangles built(blas);
  built.vertices[3 * 3 + 0] = kNan;  // X of vertex 3: triangle 1 inactive
  CHECK(HostRun(h, built.build) == Ids{});
  HostTriangles healed(blas, blas);
  CHECK(HostRun(h, healed.build) == Ids{kBecameActive});
}

}  // namespace asval::test
