// Whole-program patterns of real ray-tracing programs (shared/design/real-world-patterns.md), all valid: a layer
// that reports any of them has a false positive. Each is submitted and waited for, as the programs do.
#include <cstring>
#include <memory>

#include "corpus.h"
#include "history_helpers.h"
#include "memory_placement_helpers.h"

namespace {

using asval_test::Blas;
using asval_test::BuildInfo;
using asval_test::Commands;
using asval_test::Inputs;
using asval_test::QueryPool;
using asval_test::Shape;
using asval_test::Tlas;

constexpr auto kBuild = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
constexpr auto kUpdate = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
constexpr VkBufferUsageFlags kInputUsage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;

// Every BLAS of a scene in one call, each info with its own 128-byte aligned slice of one scratch buffer
// (more than lavapipe's required alignment), sized by what the driver reports for that build.
CORPUS_CASE(BatchedBuildsSlicedScratch, "batched-builds-sliced-scratch", "patterns",
            "64 BLAS builds in one vkCmdBuildAccelerationStructuresKHR, each on its own 128-byte aligned slice of one "
            "scratch buffer sized per build",
            {}) {
  constexpr uint32_t kCount = 64;
  Inputs inputs(device);
  std::vector<std::unique_ptr<Blas>> blases;
  std::vector<BuildInfo> builds;
  std::vector<VkDeviceSize> offsets;
  VkDeviceSize scratch_size = 0;
  for (uint32_t i = 0; i < kCount; ++i) {
    blases.push_back(std::make_unique<Blas>(device, inputs));
    Shape shape;
    shape.geometries = 1 + i % Inputs::kMaxGeometries;
    shape.triangles = 1 + i % Inputs::kMaxTriangles;
    builds.push_back(blases.back()->Info(shape));
    std::vector<uint32_t> counts(shape.geometries, shape.triangles);
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                                 &builds.back().info, counts.data(), &sizes);
    offsets.push_back(scratch_size);
    scratch_size += (sizes.buildScratchSize + 127) / 128 * 128;
  }
  vkkit::Buffer scratch = device.CreateBuffer(scratch_size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<const BuildInfo*> pointers;
  for (uint32_t i = 0; i < kCount; ++i) {
    builds[i].info.scratchData.deviceAddress = scratch.address + offsets[i];
    pointers.push_back(&builds[i]);
  }
  device.OneShot([&](VkCommandBuffer cb) { asval_test::RecordBuilds(device, cb, pointers); });
  device.Destroy(scratch);
}

// A TLAS refitted every frame from a new instance buffer (a new device address) and a new scratch buffer.
CORPUS_CASE(TlasRefitNewBuffers, "tlas-refit-new-buffers-every-frame", "patterns",
            "a TLAS built once, then updated in place every frame from a new instance buffer", {}) {
  Inputs inputs(device);
  Blas a(device, inputs), b(device, inputs);
  Tlas tlas(device);
  Commands commands(device);
  vkkit::Buffer instances = tlas.MakeInstances({&a, &b});
  VkCommandBuffer cb = commands.Begin();
  a.Build(cb, Shape{});
  b.Build(cb, Shape{});
  commands.Barrier(cb);
  tlas.Record(cb, instances, 2, kBuild);
  commands.End(cb);
  commands.Submit(cb);
  for (int frame = 0; frame < 4; ++frame) {
    vkkit::Buffer next = tlas.MakeInstances({&b, &a});
    device.OneShot([&](VkCommandBuffer frame_cb) { tlas.Record(frame_cb, next, 2, kUpdate); });
    device.Destroy(instances);
    instances = next;
  }
  device.Destroy(instances);
}

// BLAS refits every frame reading vertices from another buffer each time (written elsewhere, e.g. by a compute
// shader): addresses are not among what an update must keep.
CORPUS_CASE(BlasRefitNewInputs, "blas-refit-new-inputs-every-frame", "patterns",
            "a 2-geometry BLAS refitted in place every frame from a new vertex buffer", {}) {
  auto inputs = std::make_unique<Inputs>(device);
  Blas blas(device, *inputs);
  Shape shape;
  shape.geometries = 2;
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, shape); });
  for (int frame = 0; frame < 4; ++frame) {
    auto next = std::make_unique<Inputs>(device);
    blas.SetInputs(*next);
    inputs = std::move(next);
    device.OneShot([&](VkCommandBuffer cb) { blas.Update(cb, shape); });
  }
}

// Command buffers recorded once, in another order than they run: the update is recorded before the build and
// submitted after it. History follows submission order.
CORPUS_CASE(UpdateRecordedBeforeBuild, "update-recorded-before-build", "patterns",
            "an update recorded before its build, submitted after it; then both again in one submission", {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Shape{});
  commands.End(update);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Shape{});
  commands.End(build);
  commands.Submit(build);
  commands.Submit(update);
  commands.Submit({build, update});
}

// Per-frame command buffers recorded once and submitted every frame.
CORPUS_CASE(Resubmission, "resubmitted-refit-command-buffer", "patterns",
            "one command buffer holding a refit, recorded once and submitted 8 times after the build", {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Shape{});
  commands.End(build);
  VkCommandBuffer refit = commands.Begin();
  blas.Update(refit, Shape{});
  commands.End(refit);
  commands.Submit(build);
  for (int frame = 0; frame < 8; ++frame) commands.Submit(refit);
}

// Builds and refits recorded into secondary command buffers that a primary executes.
CORPUS_CASE(Secondaries, "builds-in-secondaries", "patterns",
            "a build and its refit recorded in two secondary command buffers, executed in order by one primary", {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = commands.BeginSecondary();
  blas.Build(build, Shape{});
  commands.End(build);
  VkCommandBuffer refit = commands.BeginSecondary();
  blas.Update(refit, Shape{});
  commands.End(refit);
  VkCommandBuffer primary = commands.Begin();
  vkCmdExecuteCommands(primary, 1, &build);
  commands.Barrier(primary);
  vkCmdExecuteCommands(primary, 1, &refit);
  commands.End(primary);
  commands.Submit(primary);
}

// Compaction as the samples do it: the query pool reset on the host, the compacted size written right after the
// build in the same command buffer; the app waits, reads it, creates smaller structures, records COMPACT copies in
// a second command buffer, destroys the originals at once, and builds the TLAS over the copies.
CORPUS_CASE(Compaction, "compaction-host-query-reset", "patterns",
            "build with ALLOW_COMPACTION, host-reset query, size query, compacting copy, originals destroyed, TLAS "
            "over the copies",
            {}) {
  Inputs inputs(device);
  auto original = std::make_unique<Blas>(device, inputs);
  Shape shape;
  shape.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR |
                VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  VkQueryPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  pool_info.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
  pool_info.queryCount = 1;
  VkQueryPool pool = VK_NULL_HANDLE;
  vkkit::Check(vkCreateQueryPool(device.handle(), &pool_info, nullptr, &pool), "vkCreateQueryPool");
  vkResetQueryPool(device.handle(), pool, 0, 1);
  device.OneShot([&](VkCommandBuffer cb) {
    original->Build(cb, shape);
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                         VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
    asval_test::CmdWriteProperties(device, cb, {original->handle()},
                                   VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool, 0);
  });
  uint64_t compacted_size = 0;
  vkkit::Check(vkGetQueryPoolResults(device.handle(), pool, 0, 1, sizeof compacted_size, &compacted_size,
                                     sizeof compacted_size, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
               "vkGetQueryPoolResults");
  vkkit::AccelerationStructure compacted =
      device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, compacted_size);
  device.OneShot([&](VkCommandBuffer cb) {
    asval_test::CmdCopy(device, cb, original->handle(), compacted.handle,
                        VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  });
  original.reset();
  // The TLAS references the compacted copy.
  VkAccelerationStructureDeviceAddressInfoKHR address_info{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  address_info.accelerationStructure = compacted.handle;
  const VkDeviceAddress compacted_address =
      device.GetAccelerationStructureDeviceAddressKHR(device.handle(), &address_info);
  Tlas tlas(device);
  vkkit::Buffer instances = tlas.MakeInstances({});
  VkAccelerationStructureInstanceKHR instance{};
  instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
  instance.mask = 0xff;
  instance.accelerationStructureReference = compacted_address;
  std::memcpy(instances.mapped, &instance, sizeof instance);
  device.OneShot([&](VkCommandBuffer cb) { tlas.Record(cb, instances, 1, kBuild); });
  device.Destroy(instances);
  device.Destroy(compacted);
  vkDestroyQueryPool(device.handle(), pool, nullptr);
}

// A sub-allocator: each frame's structure, its scratch and its vertices live in buffers bound at non-zero offsets
// of one memory block and destroyed at the end of the frame, so the next frame's buffers reuse the same device
// addresses.
CORPUS_CASE(SubAllocatedReuse, "sub-allocated-buffers-reused-every-frame", "patterns",
            "per frame, a BLAS built from buffers bound at non-zero offsets of one memory block and destroyed at "
            "frame end; the next frame reuses the addresses",
            {}) {
  asval_test::SharedMemory memory(device, 1 << 20);
  asval_test::Scene scene(device);  // only for its valid triangle geometry's shape
  for (int frame = 0; frame < 4; ++frame) {
    vkkit::Buffer vertices = memory.Bind(4096, 256, kInputUsage);
    const float triangle[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    std::memcpy(vertices.mapped, triangle, sizeof triangle);
    VkAccelerationStructureGeometryKHR geometry = scene.Triangles();
    geometry.geometry.triangles.vertexData.deviceAddress = vertices.address;
    VkAccelerationStructureBuildGeometryInfoKHR info =
        asval_test::Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
    info.pGeometries = &geometry;
    const VkAccelerationStructureBuildSizesInfoKHR sizes = asval_test::DriverSizes(device, info, {1});
    vkkit::Buffer storage = memory.Bind(65536, asval_test::RoundUp(sizes.accelerationStructureSize, 256),
                                        VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    vkkit::Buffer scratch = memory.Bind(65536 * 4, asval_test::RoundUp(sizes.buildScratchSize, 256),
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    info.dstAccelerationStructure = memory.Structure(storage, 0, sizes.accelerationStructureSize,
                                                     VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
    info.scratchData.deviceAddress = scratch.address;
    const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
    device.OneShot([&](VkCommandBuffer cb) { device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges); });
    memory.DestroyStructure(info.dstAccelerationStructure);
    memory.DestroyBuffer(scratch);
    memory.DestroyBuffer(storage);
    memory.DestroyBuffer(vertices);
  }
}

}  // namespace
