// VK_NV_ray_tracing's build, copy and property-write commands, checked when recorded (layer/checks/nv_ray_tracing.h),
// through the loader on the test driver, which implements the extension (tests/driver/nv_ray_tracing.h): its commands
// record nothing, so invalid ones are safe to pass down. Each rule fires alone; the valid twin at the end records
// every command the rules concern, well formed, and stays silent.
#include <algorithm>
#include <catch2/catch_test_macros.hpp>
#include <cstring>

#include "nv_helpers.h"

namespace asval_test {
namespace {

constexpr VkBuildAccelerationStructureFlagsNV kUpdatable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV;
constexpr VkBuildAccelerationStructureFlagsNV kCompactable = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV;

TEST_CASE(
    "nv: build arguments beyond the device's limit or dst's creation info are reported (geometryCount-02241, "
    "dst-02488)",
    "[integration][nv][structure][test-driver][passes-invalid-down]") {
  const NvDriver driver;
  HistoryFixture f("structure", {}, NvRayTracing());
  vkkit::Device& device = f.device();
  NvInputs inputs(device);
  // More geometries than maxGeometryCount, in a structure created for them.
  const std::vector<VkGeometryNV> many(kAsvalTestDriverNvMaxGeometryCount + 1, inputs.Triangles(1));
  NvStructure over(device, 0, many);
  NvStructure small(device, kUpdatable, {inputs.Triangles(1), inputs.Triangles(1)});
  NvStructure boxes(device, kUpdatable, {inputs.Aabbs(1)});
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-geometryCount-02241");
  // Against the creation info: other flags, more vertices, one geometry more, more AABBs.
  VkAccelerationStructureInfoNV flags = small.info();
  flags.flags = kCompactable;
  const VkGeometryNV bigger[2] = {inputs.Triangles(2), inputs.Triangles(1)};
  VkAccelerationStructureInfoNV counts = small.info();
  counts.pGeometries = bigger;
  const VkGeometryNV three[3] = {inputs.Triangles(1), inputs.Triangles(1), inputs.Triangles(1)};
  VkAccelerationStructureInfoNV more = small.info();
  more.geometryCount = 3;
  more.pGeometries = three;
  const VkGeometryNV two_boxes = inputs.Aabbs(2);
  VkAccelerationStructureInfoNV boxes_info = boxes.info();
  boxes_info.pGeometries = &two_boxes;
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-dst-02488", 4);
  CHECK(RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
          CmdBuildNV(device, cb, over, scratch.buffer);
          CmdBuildNV(device, cb, small, scratch.buffer, false, nullptr, &flags);
          CmdBuildNV(device, cb, small, scratch.buffer, false, nullptr, &counts);
          CmdBuildNV(device, cb, small, scratch.buffer, false, nullptr, &more);
          CmdBuildNV(device, cb, boxes, scratch.buffer, false, nullptr, &boxes_info);
        }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  device.Destroy(scratch);
}

TEST_CASE("nv: an update without src and a build into an unbound structure are reported (update-02489, dst-07787)",
          "[integration][nv][handles][test-driver]") {
  const NvDriver driver;
  HistoryFixture f("handles", {}, NvRayTracing());
  vkkit::Device& device = f.device();
  NvInputs inputs(device);
  NvStructure bound(device, kUpdatable, {inputs.Triangles(1)});
  NvStructure unbound(device, kUpdatable, {inputs.Triangles(1)}, NvStructure::Memory::kUnbound);
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-update-02489");
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-dst-07787");
  CHECK(RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
          CmdBuildNV(device, cb, bound, scratch.buffer, true, nullptr);
          CmdBuildNV(device, cb, unbound, scratch.buffer);
        }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  device.Destroy(scratch);
}

TEST_CASE(
    "nv: scratch smaller than the memory requirement or without RAY_TRACING usage, and instance data without it, "
    "are reported (update-02491, update-02492, scratch-03522, instanceData-03523)",
    "[integration][nv][addresses][test-driver]") {
  const NvDriver driver;
  HistoryFixture f("addresses", {}, NvRayTracing());
  vkkit::Device& device = f.device();
  NvInputs inputs(device);
  NvStructure blas(device, kUpdatable, {inputs.Triangles(2)});
  NvStructure tlas(device, 0, 1);
  const VkDeviceSize build = blas.Requirement(VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV);
  const VkDeviceSize update = blas.Requirement(VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV);
  REQUIRE(update < build);
  vkkit::Buffer short_build = NvBuffer(device, build - 4);
  vkkit::Buffer short_update = NvBuffer(device, update - 4);
  vkkit::Buffer storage_usage = NvBuffer(device, 1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-update-02491");
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-update-02492");
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-scratch-03522");
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-instanceData-03523");
  CHECK(RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
          CmdBuildNV(device, cb, blas, short_build.buffer);
          CmdBuildNV(device, cb, blas, short_update.buffer, true, &blas);
          CmdBuildNV(device, cb, blas, storage_usage.buffer);
          CmdBuildNV(device, cb, tlas, scratch.buffer, false, nullptr, nullptr, storage_usage.buffer);
        }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  for (vkkit::Buffer* b : {&short_build, &short_update, &storage_usage, &scratch}) device.Destroy(*b);
}

TEST_CASE("nv: an update whose src and dst are different structures over the same memory is reported (update-03526)",
          "[integration][nv][aliasing][test-driver]") {
  const NvDriver driver;
  HistoryFixture f("aliasing", {}, NvRayTracing());
  vkkit::Device& device = f.device();
  NvInputs inputs(device);
  NvStructure src(device, kUpdatable, {inputs.Triangles(1)});
  NvStructure alias(device, kUpdatable, {inputs.Triangles(1)}, NvStructure::Memory::kOwn, &src);
  vkkit::Buffer scratch = NvBuffer(device, 1 << 20);
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructureNV-update-03526");
  CHECK(RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
          CmdBuildNV(device, cb, alias, scratch.buffer, true, &src);
        }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  device.Destroy(scratch);
}

TEST_CASE(
    "nv: copies with a wrong mode, into an unbound structure or over src's memory are reported (mode-03410, "
    "dst-07792, dst-07791)",
    "[integration][nv][copies][test-driver]") {
  const NvDriver driver;
  HistoryFixture f("copies", {}, NvRayTracing());
  vkkit::Device& device = f.device();
  NvInputs inputs(device);
  NvStructure src(device, kCompactable, {inputs.Triangles(1)});
  NvStructure dst(device, kCompactable, {inputs.Triangles(1)});
  NvStructure unbound(device, kCompactable, {inputs.Triangles(1)}, NvStructure::Memory::kUnbound);
  NvStructure alias(device, kCompactable, {inputs.Triangles(1)}, NvStructure::Memory::kOwn, &src);
  const NvProcs nv(device.handle());
  f.monitor().Expect("VUID-vkCmdCopyAccelerationStructureNV-mode-03410");
  f.monitor().Expect("VUID-vkCmdCopyAccelerationStructureNV-dst-07792");
  f.monitor().Expect("VUID-vkCmdCopyAccelerationStructureNV-dst-07791");
  CHECK(RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
          nv.CmdCopy(cb, dst.handle(), src.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR);
          nv.CmdCopy(cb, unbound.handle(), src.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
          nv.CmdCopy(cb, alias.handle(), src.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
        }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "nv: property writes of another query type, into a pool of another type or of an unbound structure are "
    "reported (queryType-06216, queryPool-03755, accelerationStructure-03757)",
    "[integration][nv][copies][test-driver]") {
  const NvDriver driver;
  HistoryFixture f("copies", {}, NvRayTracing());
  vkkit::Device& device = f.device();
  NvInputs inputs(device);
  NvStructure bound(device, kCompactable, {inputs.Triangles(1)});
  NvStructure unbound(device, kCompactable, {inputs.Triangles(1)}, NvStructure::Memory::kUnbound);
  QueryPool nv_pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, 2);
  QueryPool khr_pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 2);
  const NvProcs nv(device.handle());
  const VkAccelerationStructureNV b = bound.handle(), u = unbound.handle();
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryType-06216");
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesNV-queryPool-03755");
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesNV-accelerationStructure-03757");
  CHECK(
      RunCommands(device, [&](Commands&, VkCommandBuffer cb) {
        nv_pool.Reset(cb);
        khr_pool.Reset(cb);
        // The KHR query type, into a pool of that type: 06216 alone.
        nv.CmdWriteProperties(cb, 1, &b, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, khr_pool.handle(), 0);
        // The NV type into the KHR pool: 03755 alone.
        nv.CmdWriteProperties(cb, 1, &b, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, khr_pool.handle(), 1);
        nv.CmdWriteProperties(cb, 1, &u, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, nv_pool.handle(), 0);
      }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "nv valid twin: builds, updates in place and from another structure, a top level over instance data, clones, "
    "compactions and compacted-size queries of well-formed NV structures stay silent",
    "[integration][nv][structure][handles][addresses][aliasing][copies][history][test-driver][valid]") {
  const NvDriver driver;
  HistoryFixture f(nullptr, {}, NvRayTracing());
  vkkit::Device& device = f.device();
  NvInputs inputs(device);
  const VkBuildAccelerationStructureFlagsNV both = kUpdatable | kCompactable;
  // Exactly maxGeometryCount geometries.
  const std::vector<VkGeometryNV> most(kAsvalTestDriverNvMaxGeometryCount, inputs.Triangles(1));
  NvStructure full(device, 0, most);
  NvStructure blas(device, both, {inputs.Triangles(2, true), inputs.Triangles(2)});
  NvStructure twin(device, both, {inputs.Triangles(2, true), inputs.Triangles(2)});
  NvStructure clone(device, both, {inputs.Triangles(2, true), inputs.Triangles(2)});
  NvStructure compacted(device, both, {inputs.Triangles(2, true), inputs.Triangles(2)});
  NvStructure boxes(device, both, {inputs.Aabbs(2)});
  NvStructure tlas(device, kUpdatable, 2);
  // Scratch of exactly the largest build requirement; instance data with RAY_TRACING usage.
  VkDeviceSize need = 0;
  for (const NvStructure* s : {&full, &blas, &twin, &boxes, &tlas}) {
    need = std::max(need, s->Requirement(VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV));
  }
  vkkit::Buffer scratch = NvBuffer(device, need);
  vkkit::Buffer update_scratch =
      NvBuffer(device, blas.Requirement(VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV));
  vkkit::Buffer instances = NvBuffer(device, 2 * sizeof(VkAccelerationStructureInstanceNV));
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, 1);
  const NvProcs nv(device.handle());
  // Fewer vertices and AABBs than the creation info holds room for.
  const VkGeometryNV fewer[2] = {inputs.Triangles(1, true), inputs.Triangles(1)};
  const VkGeometryNV one_box = inputs.Aabbs(1);
  VkAccelerationStructureInfoNV fewer_boxes = boxes.info();
  fewer_boxes.pGeometries = &one_box;
  VkAccelerationStructureInfoNV smaller = blas.info();
  smaller.pGeometries = fewer;
  // The top level's instances reference the bottom levels by their NV handles (accelerationStructureReference-03786).
  const VkAccelerationStructureInstanceNV records[2] = {blas.Instance(0), twin.Instance(1)};
  std::memcpy(instances.mapped, records, sizeof(records));
  CHECK(RunCommands(device, [&](Commands& commands, VkCommandBuffer cb) {
          pool.Reset(cb);
          CmdBuildNV(device, cb, full, scratch.buffer);
          commands.Barrier(cb);
          CmdBuildNV(device, cb, blas, scratch.buffer);
          commands.Barrier(cb);
          CmdBuildNV(device, cb, twin, scratch.buffer, false, nullptr, &smaller);
          commands.Barrier(cb);
          CmdBuildNV(device, cb, boxes, scratch.buffer, false, nullptr, &fewer_boxes);
          commands.Barrier(cb);
          CmdBuildNV(device, cb, tlas, scratch.buffer, false, nullptr, nullptr, instances.buffer);
          commands.Barrier(cb);
          const VkAccelerationStructureNV b = blas.handle();
          nv.CmdWriteProperties(cb, 1, &b, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, pool.handle(), 0);
        }) == VK_SUCCESS);
  CHECK(RunCommands(device, [&](Commands& commands, VkCommandBuffer cb) {
          CmdBuildNV(device, cb, blas, update_scratch.buffer, true, &blas);  // in place
          commands.Barrier(cb);
          CmdBuildNV(device, cb, twin, update_scratch.buffer, true, &blas);  // from another structure, no aliasing
          commands.Barrier(cb);
          nv.CmdCopy(cb, clone.handle(), blas.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
          nv.CmdCopy(cb, compacted.handle(), twin.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
        }) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  for (vkkit::Buffer* b : {&scratch, &update_scratch, &instances}) device.Destroy(*b);
}

}  // namespace
}  // namespace asval_test
