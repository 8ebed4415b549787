// VK_NV_ray_tracing's structures on asval's test driver (which implements the extension over lavapipe: its commands
// record nothing, tests/driver/nv_ray_tracing.h): the NV forms of the update, compaction, size, aliasing and binding
// rules, and the patterns of programs written for that extension (per-frame refits, the compaction flow), which must
// stay silent.
#include <cstring>
#include <vector>

#include "corpus.h"
#include "nv_helpers.h"

namespace {

using asval_test::CmdBuildNV;
using asval_test::Commands;
using asval_test::NvBuffer;
using asval_test::NvInputs;
using asval_test::NvProcs;
using asval_test::NvStructure;
using asval_test::QueryPool;
using asval_test::RunCommands;

constexpr const char* kNv = "nv-ray-tracing";
constexpr VkBuildAccelerationStructureFlagsNV kUpdatable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV;
constexpr VkBuildAccelerationStructureFlagsNV kCompactable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV;

CORPUS_CASE_ON_TEST_DRIVER(NvUpdateWithoutAllowUpdate, "nv-update-of-structure-built-without-allow-update", "history",
                           kNv, "a bottom level built without ALLOW_UPDATE, refit the next frame",
                           {"VUID-vkCmdBuildAccelerationStructureNV-update-02490"}) {
  NvInputs inputs(device);
  NvStructure blas(device, 0, {inputs.Triangles(2)});
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  RunCommands(device, [&](Commands&, VkCommandBuffer cb) { CmdBuildNV(device, cb, blas, scratch.buffer); });
  RunCommands(device,
              [&](Commands&, VkCommandBuffer cb) { CmdBuildNV(device, cb, blas, scratch.buffer, true, &blas); });
  device.Destroy(scratch);
}

CORPUS_CASE_ON_TEST_DRIVER(NvCompactWithoutAllowCompaction, "nv-compaction-of-structure-built-without-allow-compaction",
                           "history", kNv, "a bottom level built without ALLOW_COMPACTION, compacted into another",
                           {"VUID-vkCmdCopyAccelerationStructureNV-src-03411"}) {
  NvInputs inputs(device);
  NvStructure blas(device, 0, {inputs.Triangles(2)});
  NvStructure compact(device, 0, {inputs.Triangles(2)});
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  const NvProcs nv(device.handle());
  RunCommands(device, [&](Commands&, VkCommandBuffer cb) { CmdBuildNV(device, cb, blas, scratch.buffer); });
  RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
    nv.CmdCopy(cb, compact.handle(), blas.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  });
  device.Destroy(scratch);
}

CORPUS_CASE_ON_TEST_DRIVER(NvUpdateScratchTooSmall, "nv-build-scratch-smaller-than-requirement", "addresses", kNv,
                           "a build whose scratch buffer was sized by the update scratch requirement",
                           {"VUID-vkCmdBuildAccelerationStructureNV-update-02491"}) {
  NvInputs inputs(device);
  NvStructure blas(device, kUpdatable, {inputs.Triangles(2)});
  vkkit::Buffer scratch =
      NvBuffer(device, blas.Requirement(VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV));
  RunCommands(device, [&](Commands&, VkCommandBuffer cb) { CmdBuildNV(device, cb, blas, scratch.buffer); });
  device.Destroy(scratch);
}

CORPUS_CASE_ON_TEST_DRIVER(NvBuildBeyondCreation, "nv-build-with-more-vertices-than-created-for", "structure", kNv,
                           "a bottom level created for one triangle, built over two",
                           {"VUID-vkCmdBuildAccelerationStructureNV-dst-02488"}) {
  NvInputs inputs(device);
  NvStructure blas(device, 0, {inputs.Triangles(1)});
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  const VkGeometryNV two = inputs.Triangles(2);
  VkAccelerationStructureInfoNV info = blas.info();
  info.pGeometries = &two;
  RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
    CmdBuildNV(device, cb, blas, scratch.buffer, false, nullptr, &info);
  });
  device.Destroy(scratch);
}

CORPUS_CASE_ON_TEST_DRIVER(NvUpdateIntoAlias, "nv-update-into-structure-aliasing-its-source", "aliasing", kNv,
                           "an update from one structure into another bound to the same memory",
                           {"VUID-vkCmdBuildAccelerationStructureNV-update-03526"}) {
  NvInputs inputs(device);
  NvStructure src(device, kUpdatable, {inputs.Triangles(2)});
  NvStructure alias(device, kUpdatable, {inputs.Triangles(2)}, NvStructure::Memory::kOwn, &src);
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  RunCommands(device, [&](Commands&, VkCommandBuffer cb) { CmdBuildNV(device, cb, src, scratch.buffer); });
  RunCommands(device,
              [&](Commands&, VkCommandBuffer cb) { CmdBuildNV(device, cb, alias, scratch.buffer, true, &src); });
  device.Destroy(scratch);
}

CORPUS_CASE_ON_TEST_DRIVER(NvCopyIntoUnbound, "nv-clone-into-unbound-structure", "copies", kNv,
                           "a clone into a structure whose memory was never bound",
                           {"VUID-vkCmdCopyAccelerationStructureNV-dst-07792"}) {
  NvInputs inputs(device);
  NvStructure src(device, 0, {inputs.Triangles(2)});
  NvStructure dst(device, 0, {inputs.Triangles(2)}, NvStructure::Memory::kUnbound);
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  const NvProcs nv(device.handle());
  RunCommands(device, [&](Commands& commands, VkCommandBuffer cb) {
    CmdBuildNV(device, cb, src, scratch.buffer);
    commands.Barrier(cb);
    nv.CmdCopy(cb, dst.handle(), src.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  });
  device.Destroy(scratch);
}

CORPUS_CASE_ON_TEST_DRIVER(NvFrames, "nv-frames-refit-bottom-and-top-levels", "patterns", kNv,
                           "three frames of an NV renderer: each refits its bottom levels in place and updates the "
                           "top level over instance data that references them by their NV handles",
                           {}) {
  NvInputs inputs(device);
  NvStructure a(device, kUpdatable, {inputs.Triangles(2, true)});
  NvStructure b(device, kUpdatable, {inputs.Aabbs(2)});
  NvStructure tlas(device, kUpdatable, 2);
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  vkkit::Buffer instances = NvBuffer(device, 2 * sizeof(VkAccelerationStructureInstanceNV));
  const VkAccelerationStructureInstanceNV records[2] = {a.Instance(0), b.Instance(1)};
  std::memcpy(instances.mapped, records, sizeof(records));
  for (int frame = 0; frame < 3; ++frame) {
    const bool update = frame > 0;
    RunCommands(device, [&](Commands& commands, VkCommandBuffer cb) {
      CmdBuildNV(device, cb, a, scratch.buffer, update, update ? &a : nullptr);
      commands.Barrier(cb);
      CmdBuildNV(device, cb, b, scratch.buffer, update, update ? &b : nullptr);
      commands.Barrier(cb);
      CmdBuildNV(device, cb, tlas, scratch.buffer, update, update ? &tlas : nullptr, nullptr, instances.buffer);
    });
  }
  device.Destroy(instances);
  device.Destroy(scratch);
}

CORPUS_CASE_ON_TEST_DRIVER(NvCompactionFlow, "nv-compaction-flow-then-refit-of-the-compacted-copy", "patterns", kNv,
                           "builds with ALLOW_COMPACTION and ALLOW_UPDATE, the compacted size queried, the structure "
                           "compacted into a smaller one, the original destroyed, the compacted copy refit",
                           {}) {
  NvInputs inputs(device);
  const VkBuildAccelerationStructureFlagsNV flags = kUpdatable | kCompactable;
  auto original = std::make_unique<NvStructure>(device, flags, std::vector<VkGeometryNV>{inputs.Triangles(2)});
  NvStructure compact(device, flags, {inputs.Triangles(2)});
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, 1);
  const NvProcs nv(device.handle());
  RunCommands(device, [&](Commands& commands, VkCommandBuffer cb) {
    pool.Reset(cb);
    CmdBuildNV(device, cb, *original, scratch.buffer);
    commands.Barrier(cb);
    const VkAccelerationStructureNV handle = original->handle();
    nv.CmdWriteProperties(cb, 1, &handle, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, pool.handle(), 0);
  });
  RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
    nv.CmdCopy(cb, compact.handle(), original->handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  });
  original.reset();
  RunCommands(device,
              [&](Commands&, VkCommandBuffer cb) { CmdBuildNV(device, cb, compact, scratch.buffer, true, &compact); });
  device.Destroy(scratch);
}

}  // namespace
