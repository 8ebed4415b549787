// record_builds: what the layers cost per vkCmdBuildAccelerationStructuresKHR call while recording. Records
// CALLS valid calls into one command buffer (never submitted), with whatever layers VK_INSTANCE_LAYERS names,
// and prints the wall time per call; only the recording loop is between the callgrind client requests, so
//   valgrind --tool=callgrind --instr-atstart=no record_builds 5000 1 1 own-inputs
// with and without the layer gives the instructions per call the layer adds (run_overhead.py does this).
// Arguments: calls, infos per call, geometries per info (one triangle each), and optionally "own" (every info
// gets a scratch buffer of its own instead of a slice of one shared buffer) or "own-inputs" (also its own
// vertex buffer and its own geometry and range arrays, as an app building many meshes does; without it the
// infos share one vertex buffer and one geometry array). See docs/performance.md.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "bench_device.h"
#include "instrument.h"
#include "vkkit.h"

namespace {

int Run(int argc, char** argv) {
  const int calls = argc > 1 ? std::atoi(argv[1]) : 20000;
  const uint32_t infos_per_call = argc > 2 ? static_cast<uint32_t>(std::atoi(argv[2])) : 1;
  const uint32_t geometries_per_info = argc > 3 ? static_cast<uint32_t>(std::atoi(argv[3])) : 1;
  const bool own_inputs = argc > 4 && std::strcmp(argv[4], "own-inputs") == 0;
  const bool own_buffers = own_inputs || (argc > 4 && std::strcmp(argv[4], "own") == 0);
  if (calls < 1 || infos_per_call < 1 || geometries_per_info < 1) {
    std::fprintf(stderr, "usage: record_builds CALLS INFOS GEOMETRIES [own|own-inputs]\n");
    return 2;
  }
  overhead::BenchDevice bench;
  vkkit::Device& device = bench.device();
  vkkit::TriangleBuild build(device);
  // Every info gets geometries_per_info copies of the triangle, its own destination and its own 128-byte
  // aligned scratch slice, all sized by the driver: the calls are valid, so the layer reports nothing.
  const std::vector<VkAccelerationStructureGeometryKHR> geometries(geometries_per_info, build.geometry);
  const std::vector<VkAccelerationStructureBuildRangeInfoKHR> geometry_ranges(geometries_per_info, build.range);
  const std::vector<uint32_t> counts(geometries_per_info, build.range.primitiveCount);
  VkAccelerationStructureBuildGeometryInfoKHR info = build.info;
  info.geometryCount = geometries_per_info;
  info.pGeometries = geometries.data();
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                               counts.data(), &sizes);
  const VkDeviceSize slice = (sizes.buildScratchSize + 127) / 128 * 128;
  vkkit::Buffer scratch = device.CreateBuffer(slice * infos_per_call, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<vkkit::AccelerationStructure> destinations;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(infos_per_call, info);
  std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> ranges(infos_per_call, geometry_ranges.data());
  // "own": per info, a scratch buffer; "own-inputs": also a vertex buffer (a copy of the triangle) and
  // geometry and range arrays.
  std::vector<vkkit::Buffer> own;
  std::vector<std::vector<VkAccelerationStructureGeometryKHR>> own_geometries;
  std::vector<std::vector<VkAccelerationStructureBuildRangeInfoKHR>> own_ranges;
  for (uint32_t k = 0; k < infos_per_call; ++k) {
    destinations.push_back(device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                              sizes.accelerationStructureSize));
    infos[k].dstAccelerationStructure = destinations.back().handle;
    infos[k].scratchData.deviceAddress = scratch.address + slice * k;
    if (!own_buffers) continue;
    vkkit::Buffer own_scratch = device.CreateBuffer(slice, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    infos[k].scratchData.deviceAddress = own_scratch.address;
    own.push_back(own_scratch);
    if (!own_inputs) continue;
    vkkit::Buffer own_vertices =
        device.CreateBuffer(build.vertices.size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    std::memcpy(own_vertices.mapped, build.vertices.mapped, build.vertices.size);
    own_geometries.push_back(geometries);
    for (VkAccelerationStructureGeometryKHR& g : own_geometries.back()) {
      g.geometry.triangles.vertexData.deviceAddress = own_vertices.address;
    }
    own_ranges.push_back(geometry_ranges);
    own.push_back(own_vertices);
  }
  for (uint32_t k = 0; own_inputs && k < infos_per_call; ++k) {  // after the pushes: the arrays stay put now
    infos[k].pGeometries = own_geometries[k].data();
    ranges[k] = own_ranges[k].data();
  }

  double seconds = 0;
  device.OneShot(
      [&](VkCommandBuffer cb) {
        const auto start = std::chrono::steady_clock::now();
        OVERHEAD_START_INSTRUMENTATION;
        for (int i = 0; i < calls; ++i) {
          device.CmdBuildAccelerationStructuresKHR(cb, infos_per_call, infos.data(), ranges.data());
        }
        OVERHEAD_STOP_INSTRUMENTATION;
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      },
      /*submit=*/false);
  std::printf("%d calls x %u infos x %u geometries%s\n", calls, infos_per_call, geometries_per_info,
              own_inputs ? " (own buffers and arrays)" : own_buffers ? " (own scratch buffers)" : "");
  for (vkkit::AccelerationStructure& as : destinations) device.Destroy(as);
  for (vkkit::Buffer& b : own) device.Destroy(b);
  device.Destroy(scratch);
  build.Release(device);
  return bench.Finish(calls, seconds);
}

}  // namespace

int main(int argc, char** argv) { return overhead::Main("record_builds", Run, argc, argv); }
