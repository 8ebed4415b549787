// submit_history: what the layers cost per vkQueueSubmit of a command buffer full of acceleration-structure
// builds and updates. asval applies every recorded operation to its build history when the batch is submitted
// (docs/history.md): the update rules are checked, in submission order, against the build last executed on
// each source. Modes:
//   build-update OPS SUBMISSIONS: OPS/2 structures, each built (one call each), a barrier, then each updated in
//                                 place: OPS operations per submission;
//   update OPS SUBMISSIONS:       OPS structures built once beforehand (not measured), then a command buffer of
//                                 OPS in-place updates, one call each.
// The command buffer is recorded once and submitted SUBMISSIONS times, after one submission that is not
// measured. Only vkQueueSubmit is timed and between the callgrind client requests; the wait for the queue (where
// the driver builds, and where asval judges what it captured) is outside.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "bench_device.h"
#include "vkkit.h"

namespace {

// Builds written before the next builds read or write.
void BuildBarrier(VkCommandBuffer cb) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  barrier.dstAccessMask =
      VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR;
  vkCmdPipelineBarrier(cb, stage, stage, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

int Run(int argc, char** argv) {
  const bool build_update = argc > 1 && std::strcmp(argv[1], "build-update") == 0;
  const bool update_only = argc > 1 && std::strcmp(argv[1], "update") == 0;
  const int operations = argc > 2 ? std::atoi(argv[2]) : 1000;
  const int submissions = argc > 3 ? std::atoi(argv[3]) : 10;
  if (!(build_update || update_only) || operations < 2 || submissions < 1) {
    std::fprintf(stderr, "usage: submit_history build-update|update OPERATIONS SUBMISSIONS\n");
    return 2;
  }
  overhead::BenchDevice bench;
  vkkit::Device& device = bench.device();
  const VkDevice handle = device.handle();
  const uint32_t structures = static_cast<uint32_t>(build_update ? operations / 2 : operations);

  // One triangle per structure, updatable; every structure gets its own storage and its own scratch slice
  // (large enough for a build or an update), so that no two operations of the batch share memory.
  vkkit::TriangleBuild triangle(device);
  VkAccelerationStructureBuildGeometryInfoKHR info = triangle.info;
  info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  info.pGeometries = &triangle.geometry;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(handle, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                               &triangle.range.primitiveCount, &sizes);
  const VkDeviceSize alignment = device.as_properties().minAccelerationStructureScratchOffsetAlignment;
  const VkDeviceSize needed =
      sizes.buildScratchSize > sizes.updateScratchSize ? sizes.buildScratchSize : sizes.updateScratchSize;
  const VkDeviceSize slice = (needed + alignment - 1) / alignment * alignment;
  vkkit::Buffer scratch = device.CreateBuffer(slice * structures, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<vkkit::AccelerationStructure> blases;
  for (uint32_t i = 0; i < structures; ++i) {
    blases.push_back(device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                        sizes.accelerationStructureSize));
  }
  const VkAccelerationStructureBuildRangeInfoKHR* range = &triangle.range;
  auto record = [&](VkCommandBuffer cb, VkBuildAccelerationStructureModeKHR mode) {
    for (uint32_t i = 0; i < structures; ++i) {
      VkAccelerationStructureBuildGeometryInfoKHR one = info;
      one.mode = mode;
      one.dstAccelerationStructure = blases[i].handle;
      const bool update = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
      one.srcAccelerationStructure = update ? blases[i].handle : VK_NULL_HANDLE;
      one.scratchData.deviceAddress = scratch.address + slice * i;
      device.CmdBuildAccelerationStructuresKHR(cb, 1, &one, &range);
    }
  };

  const VkCommandPool pool = overhead::CreatePool(bench.gpu(), handle);
  if (update_only) {  // the builds the updates start from, executed before anything is measured
    VkCommandBuffer first = overhead::BeginReusable(handle, pool);
    record(first, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    vkkit::Check(vkEndCommandBuffer(first), "vkEndCommandBuffer");
    overhead::TimeSubmissions(device.queue(), first, 0);  // submitted once, not measured
  }
  VkCommandBuffer cb = overhead::BeginReusable(handle, pool);
  if (build_update) {
    record(cb, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    BuildBarrier(cb);
  }
  record(cb, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  BuildBarrier(cb);  // the next submission's operations come after this one's
  vkkit::Check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");

  const double seconds = overhead::TimeSubmissions(device.queue(), cb, submissions);
  std::printf("%d submissions of %d operations (%s)\n", submissions, build_update ? 2 * structures : structures,
              build_update ? "builds, then updates" : "updates");
  vkDestroyCommandPool(handle, pool, nullptr);
  for (vkkit::AccelerationStructure& as : blases) device.Destroy(as);
  device.Destroy(scratch);
  triangle.Release(device);
  return bench.Finish(submissions, seconds);
}

}  // namespace

int main(int argc, char** argv) { return overhead::Main("submit_history", Run, argc, argv); }
