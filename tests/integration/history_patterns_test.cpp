// Real programs' valid uses of build history (design/real-world-patterns.md), every family on: all silent.
#include <catch2/catch_test_macros.hpp>

#include "history_helpers.h"

namespace asval_test {
namespace {

TEST_CASE("history pattern: in-place updates every frame with new input buffers stay silent",
          "[integration][history][patterns]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  auto inputs = std::make_unique<Inputs>(device);
  Blas blas(device, *inputs);
  Shape shape;
  shape.geometries = 2;
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, shape); });
  for (int frame = 0; frame < 4; ++frame) {
    auto next = std::make_unique<Inputs>(device);  // vertices written elsewhere this frame
    blas.SetInputs(*next);
    inputs = std::move(next);
    device.OneShot([&](VkCommandBuffer cb) { blas.Update(cb, shape); });
  }
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history pattern: a refit in a separate one-shot command buffer after a host wait stays silent",
          "[integration][history][patterns]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, Shape{}); });  // waits on the host (vkQueueWaitIdle)
  device.OneShot([&](VkCommandBuffer cb) { blas.Update(cb, Shape{}); });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history pattern: many infos per call, then their updates in one call, stay silent",
          "[integration][history][patterns]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Procs procs(device);
  Inputs inputs(device);
  std::vector<std::unique_ptr<Blas>> blases;
  std::vector<Shape> shapes(3);
  for (uint32_t i = 0; i < 3; ++i) {
    blases.push_back(std::make_unique<Blas>(device, inputs));
    shapes[i].geometries = i + 1;
  }
  // One call with an info per structure (ppGeometries, as some engines pass them).
  const auto record_all = [&](VkCommandBuffer cb, VkBuildAccelerationStructureModeKHR mode) {
    std::vector<BuildInfo> builds;
    for (uint32_t i = 0; i < 3; ++i) builds.push_back(MakeBuildInfo(shapes[i], inputs));
    std::vector<std::vector<const VkAccelerationStructureGeometryKHR*>> pointers(3);
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
    std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges;
    std::vector<vkkit::Buffer> scratch;
    for (uint32_t i = 0; i < 3; ++i) {
      for (const auto& g : builds[i].geometries) pointers[i].push_back(&g);
      VkAccelerationStructureBuildGeometryInfoKHR info = builds[i].info;
      info.pGeometries = nullptr;
      info.ppGeometries = pointers[i].data();
      info.mode = mode;
      info.srcAccelerationStructure = mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? blases[i]->handle()
                                                                                              : VK_NULL_HANDLE;
      info.dstAccelerationStructure = blases[i]->handle();
      scratch.push_back(device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT));
      info.scratchData.deviceAddress = scratch.back().address;
      infos.push_back(info);
      ranges.push_back(builds[i].range_pointer);
    }
    procs.CmdBuild(cb, 3, infos.data(), ranges.data());
    return scratch;
  };
  std::vector<vkkit::Buffer> scratch;
  device.OneShot([&](VkCommandBuffer cb) { scratch = record_all(cb, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR); });
  for (auto& b : scratch) device.Destroy(b);
  device.OneShot(
      [&](VkCommandBuffer cb) { scratch = record_all(cb, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR); });
  for (auto& b : scratch) device.Destroy(b);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history pattern: a TLAS updated every frame from a new instance buffer stays silent",
          "[integration][history][patterns]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas a(device, inputs), b(device, inputs);
  Tlas tlas(device);
  vkkit::Buffer instances = tlas.MakeInstances({&a, &b});
  device.OneShot([&](VkCommandBuffer cb) {
    a.Build(cb, Shape{});
    b.Build(cb, Shape{});
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                         VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
    tlas.Record(cb, instances, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  for (int frame = 0; frame < 4; ++frame) {
    vkkit::Buffer next = tlas.MakeInstances({&b, &a});  // a new buffer (a new address) each frame
    device.OneShot(
        [&](VkCommandBuffer cb) { tlas.Record(cb, next, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR); });
    device.Destroy(instances);
    instances = next;
  }
  device.Destroy(instances);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
