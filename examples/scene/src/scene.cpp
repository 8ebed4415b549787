#include "scene.h"

#include <chrono>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <vector>

#include "png_file.h"

namespace scene {

namespace {

std::vector<Prototype> Prototypes(const StaticBlases& s, const DeformingBlases& d) {
  using K = StaticBlases;
  return {{s.structure(K::kRock).address, 0, 0.9f, 30},   {s.structure(K::kTorus).address, 0, 0.9f, 18},
          {s.structure(K::kCrates).address, 0, 1.0f, 18}, {s.structure(K::kSpheres).address, 1, 0.35f, 10},
          {d.flag().address, 0, 0.8f, 6},                 {d.blob().address, 0, 1.0f, 8}};
}

}  // namespace

Scene::Scene(Gpu& g, Findings& f, const SceneOptions& o)
    : gpu(g),
      findings(f),
      options(o),
      statics(g),
      deforming(g),
      top(g, o.instances, Prototype{statics.structure(StaticBlases::kGround).address, 0, 1.0f, 0},
          Prototypes(statics, deforming)),
      tracer(g, o.width, o.height),
      crowd(g, deforming, o.refits) {
  tracer.SetScene(top.structure().handle);
  const float eye[3] = {1.5f, 4.5f, 12.0f};
  const float target[3] = {0.0f, 0.8f, 0.0f};
  tracer.SetCamera(eye, target, 50.0f);
  RecordCommandBuffers();
}

Scene::~Scene() {
  vkDeviceWaitIdle(gpu.device());
  for (VkCommandBuffer cb : {first_, trace_}) gpu.FreeCommandBuffer(cb);
  for (uint32_t p = 0; p < 2; ++p) {
    for (VkCommandBuffer cb : {refit_[p], tlas_update_[p], tlas_build_[p]}) gpu.FreeCommandBuffer(cb);
  }
}

VkCommandBuffer Scene::Record(VkCommandBufferUsageFlags flags, const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBuffer cb = gpu.AllocateCommandBuffer();
  gpu.Begin(cb, flags);
  record(cb);
  gpu.End(cb);
  return cb;
}

void Scene::RecordCommandBuffers() {
  const VkBuildAccelerationStructureModeKHR kBuild = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  const VkBuildAccelerationStructureModeKHR kUpdate = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  // Reused every frame (no ONE_TIME_SUBMIT): submitted many times, waited for in between.
  for (uint32_t p = 0; p < 2; ++p) {
    refit_[p] = Record(0, [&](VkCommandBuffer cb) {
      deforming.RecordAnimate(cb, p);
      deforming.RecordBuilds(cb, p, kUpdate);
      crowd.RecordBuilds(cb, p, kUpdate);
    });
    tlas_update_[p] = Record(0, [&](VkCommandBuffer cb) { top.RecordBuild(cb, p, kUpdate); });
    tlas_build_[p] = Record(0, [&](VkCommandBuffer cb) { top.RecordBuild(cb, p, kBuild); });
  }
  trace_ = Record(0, [&](VkCommandBuffer cb) { tracer.RecordTrace(cb); });
  // Recorded last, executed first.
  first_ = Record(VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT, [&](VkCommandBuffer cb) {
    deforming.RecordAnimate(cb, 0);
    deforming.RecordBuilds(cb, 0, kBuild);
    crowd.RecordBuilds(cb, 0, kBuild);
  });
  const char* names[] = {"refit (even frames)", "refit (odd frames)", "TLAS update (even frames)",
                         "TLAS update (odd frames)", "TLAS build (even frames)", "TLAS build (odd frames)"};
  for (uint32_t p = 0; p < 2; ++p) {
    gpu.Name(VK_OBJECT_TYPE_COMMAND_BUFFER, refit_[p], names[p]);
    gpu.Name(VK_OBJECT_TYPE_COMMAND_BUFFER, tlas_update_[p], names[2 + p]);
    gpu.Name(VK_OBJECT_TYPE_COMMAND_BUFFER, tlas_build_[p], names[4 + p]);
  }
  gpu.Name(VK_OBJECT_TYPE_COMMAND_BUFFER, trace_, "trace");
  gpu.Name(VK_OBJECT_TYPE_COMMAND_BUFFER, first_, "first build of the deforming structures");
}

void Scene::Frame(uint32_t frame) {
  if (options.static_scene && frame > 0) {  // the structures of frame 0 stay as they are
    Check(gpu.SubmitAndWait({trace_}), "frame: vkQueueSubmit");
    return;
  }
  const uint32_t p = frame % 2;
  const float t = TimeOf(frame);
  deforming.params().time = t;
  top.WriteInstances(p, t);
  VkResult result;
  if (frame == 0) {
    result = gpu.SubmitAndWait({first_, tlas_build_[0], trace_});
  } else {
    result = gpu.SubmitAndWait({refit_[p], frame % 4 == 0 ? tlas_build_[p] : tlas_update_[p], trace_});
  }
  Check(result, "frame: vkQueueSubmit");
}

void Scene::RunFrames() {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  Clock::time_point after_first = start;
  for (uint32_t f = 0; f < options.frames; ++f) {
    Frame(f);
    if (f == 0) after_first = Clock::now();
    ++frames_done_;
    if (after_frame) after_frame(frames_done_);
  }
  const double first_ms = std::chrono::duration<double, std::milli>(after_first - start).count();
  const double rest_s = std::chrono::duration<double>(Clock::now() - after_first).count();
  std::printf("frames: %u; frame 0 (builds) %.1f ms", options.frames, first_ms);
  if (options.frames > 1) {
    std::printf("; frames 1..%u (%s) %.2f fps", options.frames - 1, options.static_scene ? "trace only" : "refits",
                (options.frames - 1) / rest_s);
  }
  std::printf("\n");
}

void Scene::WriteImage(const std::string& path) const {
  WritePng(path, tracer.pixels(), tracer.width(), tracer.height());
  std::printf("wrote %s (%ux%u)\n", path.c_str(), tracer.width(), tracer.height());
}

}  // namespace scene
