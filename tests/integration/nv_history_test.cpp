// VK_NV_ray_tracing's rules on what executed before (update-02490, src-04963, src-03411, pAccelerationStructures-04958
// and 06215): judged at submission, in execution order, on the history the NV commands share with the KHR ones
// (layer/state/nv_structures.h), through the loader on the test driver (tests/driver/nv_ray_tracing.h).
#include <catch2/catch_test_macros.hpp>

#include "nv_helpers.h"

namespace asval_test {
namespace {

constexpr VkBuildAccelerationStructureFlagsNV kUpdatable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV;
constexpr VkBuildAccelerationStructureFlagsNV kCompactable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV;
constexpr VkQueryType kCompactedSizeNV = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV;

// What every test here uses: inputs, a scratch buffer large enough for any of their builds, the NV commands.
struct NvProgram {
  explicit NvProgram(vkkit::Device& d) : device(d), inputs(d), scratch(NvBuffer(d, 1 << 20)), nv(d.handle()) {}
  ~NvProgram() { device.Destroy(scratch); }
  vkkit::Device& device;
  NvInputs inputs;
  vkkit::Buffer scratch;
  NvProcs nv;
};

template <typename Recorder>
VkCommandBuffer Record(Commands& commands, Recorder&& record) {
  VkCommandBuffer cb = commands.Begin();
  record(cb);
  commands.End(cb);
  return cb;
}

TEST_CASE(
    "nv history: updates from a structure built without ALLOW_UPDATE, or never built, are reported when "
    "submitted (update-02490)",
    "[integration][nv][history][test-driver][passes-invalid-down]") {
  const NvDriver driver;
  HistoryFixture f("history", {}, NvRayTracing());
  NvProgram p(f.device());
  NvStructure fixed(p.device, 0, {p.inputs.Triangles(1)});
  NvStructure never(p.device, kUpdatable, {p.inputs.Triangles(1)});
  NvStructure dst(p.device, 0, {p.inputs.Triangles(1)});
  NvStructure dst2(p.device, kUpdatable, {p.inputs.Triangles(1)});
  Commands commands(p.device);
  VkCommandBuffer build =
      Record(commands, [&](VkCommandBuffer cb) { CmdBuildNV(p.device, cb, fixed, p.scratch.buffer); });
  REQUIRE(commands.Submit(build) == VK_SUCCESS);
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-update-02490", 2);
  VkCommandBuffer updates = Record(commands, [&](VkCommandBuffer cb) {
    CmdBuildNV(p.device, cb, dst, p.scratch.buffer, true, &fixed);
    CmdBuildNV(p.device, cb, dst2, p.scratch.buffer, true, &never);
  });
  CHECK(commands.Submit(updates) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "nv history: a copy from a never-built structure and a compaction of one built without ALLOW_COMPACTION are "
    "reported when submitted (src-04963, src-03411)",
    "[integration][nv][history][test-driver][passes-invalid-down]") {
  const NvDriver driver;
  HistoryFixture f("history", {}, NvRayTracing());
  NvProgram p(f.device());
  NvStructure never(p.device, kCompactable, {p.inputs.Triangles(1)});
  NvStructure plain(p.device, 0, {p.inputs.Triangles(1)});
  NvStructure dst(p.device, 0, {p.inputs.Triangles(1)});
  Commands commands(p.device);
  REQUIRE(RunCommands(commands, [&](VkCommandBuffer cb) { CmdBuildNV(p.device, cb, plain, p.scratch.buffer); }) ==
          VK_SUCCESS);
  f.monitor().Expect("VUID-vkCmdCopyAccelerationStructureNV-src-04963");
  f.monitor().Expect("VUID-vkCmdCopyAccelerationStructureNV-src-03411");
  CHECK(RunCommands(commands, [&](VkCommandBuffer cb) {
          p.nv.CmdCopy(cb, dst.handle(), never.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
          p.nv.CmdCopy(cb, dst.handle(), plain.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
        }) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "nv history: compacted-size queries of a never-built structure and of one built without ALLOW_COMPACTION "
    "are reported when submitted (pAccelerationStructures-04958, pAccelerationStructures-06215)",
    "[integration][nv][history][test-driver][passes-invalid-down]") {
  const NvDriver driver;
  HistoryFixture f("history", {}, NvRayTracing());
  NvProgram p(f.device());
  NvStructure never(p.device, kCompactable, {p.inputs.Triangles(1)});
  NvStructure plain(p.device, 0, {p.inputs.Triangles(1)});
  QueryPool pool(p.device, kCompactedSizeNV, 2);
  Commands commands(p.device);
  REQUIRE(RunCommands(commands, [&](VkCommandBuffer cb) { CmdBuildNV(p.device, cb, plain, p.scratch.buffer); }) ==
          VK_SUCCESS);
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-04958");
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesNV-pAccelerationStructures-06215");
  const VkAccelerationStructureNV structures[2] = {never.handle(), plain.handle()};
  CHECK(RunCommands(commands, [&](VkCommandBuffer cb) {
          pool.Reset(cb);
          p.nv.CmdWriteProperties(cb, 2, structures, kCompactedSizeNV, pool.handle(), 0);
        }) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "nv history valid twin: updates, copies and compacted-size queries recorded before the builds they depend "
    "on, but submitted after them, stay silent; so do clones of clones and updates of a clone",
    "[integration][nv][history][test-driver][valid]") {
  const NvDriver driver;
  HistoryFixture f("history", {}, NvRayTracing());
  NvProgram p(f.device());
  const VkBuildAccelerationStructureFlagsNV both = kUpdatable | kCompactable;
  NvStructure a(p.device, both, {p.inputs.Triangles(2)});
  NvStructure b(p.device, both, {p.inputs.Triangles(2)});
  NvStructure c(p.device, both, {p.inputs.Triangles(2)});
  QueryPool pool(p.device, kCompactedSizeNV, 1);
  Commands commands(p.device);
  // Recorded first: depends on a's build.
  VkCommandBuffer later = Record(commands, [&](VkCommandBuffer cb) {
    pool.Reset(cb);
    CmdBuildNV(p.device, cb, a, p.scratch.buffer, true, &a);
    commands.Barrier(cb);
    const VkAccelerationStructureNV handle = a.handle();
    p.nv.CmdWriteProperties(cb, 1, &handle, kCompactedSizeNV, pool.handle(), 0);
    p.nv.CmdCopy(cb, b.handle(), a.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
    commands.Barrier(cb);
    p.nv.CmdCopy(cb, c.handle(), b.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
    commands.Barrier(cb);
    CmdBuildNV(p.device, cb, c, p.scratch.buffer, true, &c);
  });
  VkCommandBuffer first = Record(commands, [&](VkCommandBuffer cb) { CmdBuildNV(p.device, cb, a, p.scratch.buffer); });
  CHECK(commands.Submit(first) == VK_SUCCESS);
  CHECK(commands.Submit(later) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
