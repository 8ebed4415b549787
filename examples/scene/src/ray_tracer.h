#pragma once
// The ray-tracing pass: a pipeline with one ray generation shader, two miss shaders (sky, shadow) and two hit
// groups (triangles; procedural spheres with an intersection shader), its shader binding table, and an image
// kept as packed RGBA8 in a host-visible buffer.
#include <array>
#include <cstdint>

#include "gpu.h"

namespace scene {

class RayTracer {
 public:
  RayTracer(Gpu& gpu, uint32_t width, uint32_t height);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  void SetScene(VkAccelerationStructureKHR tlas);  // the descriptor
  void SetCamera(const float eye[3], const float target[3], float vertical_fov_degrees);
  // Traces, then makes the image visible to the host.
  void RecordTrace(VkCommandBuffer cb) const;

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  const uint32_t* pixels() const { return static_cast<const uint32_t*>(image_.mapped); }

 private:
  void CreatePipeline();
  void CreateShaderBindingTable();

  Gpu& gpu_;
  uint32_t width_;
  uint32_t height_;
  Buffer image_;
  Buffer camera_;
  Buffer sbt_;
  VkStridedDeviceAddressRegionKHR raygen_region_{};
  VkStridedDeviceAddressRegionKHR miss_region_{};
  VkStridedDeviceAddressRegionKHR hit_region_{};
  VkStridedDeviceAddressRegionKHR callable_region_{};
  PipelineObjects pipe_;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

}  // namespace scene
