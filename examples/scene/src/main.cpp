// asval_scene: the bundled sample scene. Renders an animated ray-traced scene headless, the way engines use
// acceleration structures (see README and docs/scene.md), optionally commits one named rule violation, and
// prints what the validation layers reported. Exit status: 0 when it ran (findings or not), 1 when it could
// not run, 2 on a bad command line.
#include <cstdio>
#include <exception>
#include <string>

#include "faults.h"
#include "findings.h"
#include "frame_checkpoints.h"
#include "gpu.h"
#include "inject.h"
#include "options.h"
#include "protect_settings.h"
#include "scene.h"
#include "vkkit.h"

namespace {

// Prints the --checkpoints lines while the scene runs its frames.
class FrameCheckpointsHook {
 public:
  FrameCheckpointsHook(scene::Scene& world, const scene::SceneOptions& options) : checkpoints_(options.checkpoints) {
    if (options.checkpoints.empty()) return;
    checkpoints_.Start();
    world.after_frame = [this](uint32_t frames_done) { checkpoints_.AfterFrame(frames_done); };
  }

 private:
  scene::FrameCheckpoints checkpoints_;
};

int Run(const scene::SceneOptions& options) {
  scene::Findings findings;
  {
    // The messenger is chained into the create info too, so messages of vkCreateInstance and
    // vkDestroyInstance arrive. Layers come from the environment, as for any application. A fault run also
    // turns on asval's protect mode and listens to its notices; a plain run asks for nothing more.
    const bool fault_run = options.fault != nullptr;
    const VkDebugUtilsMessengerCreateInfoEXT messenger = findings.CreateInfo(fault_run);
    const scene::ProtectSettings protect(&messenger);
    vkkit::InstanceOptions instance_options;
    instance_options.pNext = fault_run ? protect.chain() : &messenger;
    vkkit::Instance instance(instance_options);
    findings.Attach(instance.handle(), fault_run);
    struct DetachFirst {  // the messenger goes before the instance, also when something throws
      scene::Findings& findings;
      ~DetachFirst() { findings.Detach(); }
    } detach_first{findings};
    const VkPhysicalDevice physical = scene::Gpu::FindRayTracingDevice(instance.handle());
    if (!physical) {
      std::fprintf(stderr, "asval_scene: no device with VK_KHR_acceleration_structure and VK_KHR_ray_tracing_pipeline\n");
      return 1;
    }
    {
      scene::Gpu gpu(instance.handle(), physical);
      scene::Scene world(gpu, findings, options);
      std::printf("device: %s; %u instances (%u inactive); static structures %llu bytes, %llu after compaction\n",
                  gpu.name().c_str(), world.top.count(), world.top.inactive(),
                  static_cast<unsigned long long>(world.statics.built_bytes()),
                  static_cast<unsigned long long>(world.statics.compacted_bytes()));
      std::printf("deforming: %u inactive triangles (NaN), %u degenerate at the first build\n",
                  world.deforming.meshes().inactive_triangles, world.deforming.meshes().degenerate_triangles);
      if (world.crowd.count()) {
        std::printf("crowd: %u more bottom-level structures refit per frame, one vkCmdBuildAccelerationStructuresKHR each\n",
                    world.crowd.count());
      }
      std::fflush(stdout);
      FrameCheckpointsHook checkpoints(world, options);
      world.RunFrames();
      if (!options.out.empty()) world.WriteImage(options.out);
      if (options.fault) scene::InjectFault(world, *options.fault);
    }
  }
  // Everything is destroyed: a layer that reports late (at a wait, or at vkDestroyDevice) has reported.
  std::printf("validation messages: %u error(s), %u warning(s)\n", findings.errors(), findings.warnings());
  if (options.fault) {
    const scene::FaultInfo& f = *options.fault;
    bool reported = false;
    for (const scene::Finding& x : findings.all()) reported = reported || x.vuid == f.vuid;
    std::printf("fault %s: expected %s: %s\n", f.name, f.vuid, reported ? "reported" : "NOT reported");
    std::printf("fault %s: %u %s notice(s)\n", f.name, findings.withheld_notices(), scene::kWithheldNoticeId);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  scene::SceneOptions options;
  std::string error;
  if (!scene::ParseOptions(argc, argv, &options, &error)) {
    std::fprintf(stderr, "asval_scene: %s\n%s", error.c_str(), scene::Usage());
    return 2;
  }
  if (options.help) {
    std::printf("%s", scene::Usage());
    return 0;
  }
  if (options.list_faults) {
    scene::PrintFaults(stdout);
    return 0;
  }
  try {
    return Run(options);
  } catch (const std::exception& e) {
    std::fflush(stdout);
    std::fprintf(stderr, "asval_scene: %s\n", e.what());
    return 1;
  }
}
