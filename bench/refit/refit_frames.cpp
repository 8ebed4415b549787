// refit_frames: the heavy-refit frame of issue 27. Each frame, in one command buffer recorded anew: a compute
// shader moves the vertices of N bottom-level structures, the N structures are refit in place (N calls of one
// info, or one call of N infos), then one top-level structure over them is updated. Submitted, waited for with a
// fence, its GPU time read from two timestamps. A valid program: the overhead benchmark's device counts every
// validation message, and the run fails (exit 3) if a layer reported anything.
//
// Prints, besides the device, the active layers and the message counts (bench/overhead/bench_device.h):
//   refit: structures N triangles T shape calls|one-call frames F
//   result: record_ms=R submit_wait_ms=S gpu_ms=G frame_ms=M
// the per-frame means of the measured frames (gpu_ms=- without timestamps). Under callgrind
// (valgrind --tool=callgrind --instr-atstart=no) only the measured frames are instrumented.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "bench_device.h"
#include "bottom_levels.h"
#include "device_buffers.h"
#include "frame_commands.h"
#include "gpu_timer.h"
#include "grid_mesh.h"
#include "instrument.h"
#include "refit_options.h"
#include "top_level.h"
#include "vertex_mover.h"
#include "vkkit.h"

namespace {

using Clock = std::chrono::steady_clock;

double Milliseconds(Clock::time_point from, Clock::time_point to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

struct FrameTimes {
  double record_ms = 0;       // reset the pool, begin, record, end
  double submit_wait_ms = 0;  // vkQueueSubmit, then the wait for the frame's fence
  double gpu_ms = 0;          // between the command buffer's first and last timestamps
  double frame_ms = 0;        // all of it, the timestamps' read-back included
  void Add(const FrameTimes& f) {
    record_ms += f.record_ms;
    submit_wait_ms += f.submit_wait_ms;
    gpu_ms += f.gpu_ms;
    frame_ms += f.frame_ms;
  }
};

// The mesh's buffers: the rest positions the shader reads, the indices every structure shares, and the moved
// positions (all structures') the shader writes and the refits read.
struct MeshBuffers {
  vkkit::Buffer rest, indices, positions;
  MeshBuffers(vkkit::Device& device, const refit::GridMesh& mesh, uint32_t structures) : device_(device) {
    rest = refit::UploadToDevice(device, mesh.rest.data(), mesh.rest.size() * sizeof(float),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    indices = refit::UploadToDevice(device, mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t),
                                    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    positions = refit::CreateDeviceLocalBuffer(
        device, VkDeviceSize{structures} * mesh.vertex_count() * 3 * sizeof(float),
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  }
  ~MeshBuffers() {
    device_.Destroy(positions);
    device_.Destroy(indices);
    device_.Destroy(rest);
  }
  MeshBuffers(const MeshBuffers&) = delete;
  MeshBuffers& operator=(const MeshBuffers&) = delete;

 private:
  vkkit::Device& device_;
};

// Everything a frame records, in destruction order (the users of the mesh's buffers before the buffers).
struct RefitWorld {
  MeshBuffers buffers;
  refit::VertexMover mover;
  refit::BottomLevels bottom;
  refit::TopLevel top;
  RefitWorld(vkkit::Device& device, const refit::GridMesh& mesh, uint32_t structures)
      : buffers(device, mesh, structures),
        mover(device, buffers.rest, buffers.positions, mesh.vertex_count(), structures),
        bottom(device, buffers.positions, buffers.indices, mesh.vertex_count(), mesh.triangle_count(), structures),
        top(device, bottom.addresses()) {}
};

int Run(int argc, char** argv) {
  refit::RefitOptions options;
  std::string error;
  if (!refit::ParseRefitOptions(argc, argv, &options, &error)) {
    std::fprintf(stderr, "refit_frames: %s\n%s", error.c_str(), refit::RefitUsage());
    return 2;
  }
  if (options.help) {
    std::printf("%s", refit::RefitUsage());
    return 0;
  }
  overhead::BenchDevice bench;
  vkkit::Device& device = bench.device();
  const refit::GridMesh mesh = refit::MakeGridMesh(options.triangles);
  FrameTimes sum;
  {
    RefitWorld world(device, mesh, options.structures);
    refit::GpuTimer timer(device, bench.gpu());
    refit::FrameCommands commands(device, bench.gpu());

    // Frame 0 builds every structure; every later frame refits them in place.
    auto frame = [&](uint32_t index) {
      const VkBuildAccelerationStructureModeKHR mode =
          index == 0 ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
      FrameTimes t;
      const Clock::time_point start = Clock::now();
      VkCommandBuffer cb = commands.Begin();
      timer.RecordStart(cb);
      world.mover.Record(cb, 0.05f * static_cast<float>(index));
      world.bottom.Record(cb, mode, options.shape);
      world.top.Record(cb, mode);
      timer.RecordEnd(cb);
      commands.End();
      const Clock::time_point recorded = Clock::now();
      // The previous frame's fence was waited for: its builds no longer read what this frame writes.
      commands.SubmitAndWait();
      const Clock::time_point done = Clock::now();
      t.gpu_ms = timer.ReadMilliseconds();
      t.record_ms = Milliseconds(start, recorded);
      t.submit_wait_ms = Milliseconds(recorded, done);
      t.frame_ms = Milliseconds(start, Clock::now());
      return t;
    };

    uint32_t index = 0;
    frame(index++);
    for (uint32_t w = 0; w < options.warmup; ++w) frame(index++);
    OVERHEAD_START_INSTRUMENTATION;
    for (uint32_t f = 0; f < options.frames; ++f) sum.Add(frame(index++));
    OVERHEAD_STOP_INSTRUMENTATION;

    const double frames = options.frames;
    std::printf("refit: structures %u triangles %u shape %s frames %u\n", options.structures, mesh.triangle_count(),
                refit::ShapeName(options.shape), options.frames);
    const std::string gpu = timer.available() ? std::to_string(sum.gpu_ms / frames) : "-";
    std::printf("result: record_ms=%.6f submit_wait_ms=%.6f gpu_ms=%s frame_ms=%.6f\n", sum.record_ms / frames,
                sum.submit_wait_ms / frames, gpu.c_str(), sum.frame_ms / frames);
  }
  // Destroys the device (its messages count too) and prints the message counts; exit 3 if there were any.
  return bench.Finish(options.frames, sum.frame_ms * 1e-3);
}

}  // namespace

int main(int argc, char** argv) { return overhead::Main("refit_frames", Run, argc, argv); }
