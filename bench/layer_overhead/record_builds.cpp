// record_builds: the cost of the layer on the hot path. Records N vkCmdBuildAccelerationStructuresKHR calls
// (valid, never submitted) into one command buffer, with whatever layers the environment enables, and
// prints the wall time per call. Under callgrind only the recording loop is instrumented, so
//   valgrind --tool=callgrind --instr-atstart=no ./record_builds 20000
// with and without VK_INSTANCE_LAYERS=VK_LAYER_ASVAL_as_validation gives the instructions per call that the
// layer adds (the difference of the two totals divided by N). See docs/performance.md.
#include <valgrind/callgrind.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "vkkit.h"

int main(int argc, char** argv) {
  const int calls = argc > 1 ? std::atoi(argv[1]) : 20000;
  const uint32_t infos_per_call = argc > 2 ? static_cast<uint32_t>(std::atoi(argv[2])) : 1;
  vkkit::InstanceOptions options;  // layers from VK_INSTANCE_LAYERS
  vkkit::Instance instance(options);
  VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  if (!gpu) {
    std::fprintf(stderr, "no device with VK_KHR_acceleration_structure\n");
    return 1;
  }
  vkkit::Device device(instance, gpu);
  vkkit::TriangleBuild build(device);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(infos_per_call, build.info);
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges(infos_per_call, &build.range);
  for (auto& info : infos) info.pGeometries = &build.geometry;

  double seconds = 0;
  device.OneShot(
      [&](VkCommandBuffer cb) {
        const auto start = std::chrono::steady_clock::now();
        CALLGRIND_START_INSTRUMENTATION;
        for (int i = 0; i < calls; ++i) {
          device.CmdBuildAccelerationStructuresKHR(cb, infos_per_call, infos.data(), ranges.data());
        }
        CALLGRIND_STOP_INSTRUMENTATION;
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      },
      /*submit=*/false);
  std::printf("%d calls x %u infos: %.1f ns per call\n", calls, infos_per_call, seconds * 1e9 / calls);
  build.Release(device);
  return 0;
}
