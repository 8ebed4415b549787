#pragma once
// Trace and ray-query work for the family traces (issue 29): a pipeline that reads a top-level structure through a
// descriptor (set 0, binding 0) and writes whether its one ray hit into a storage buffer (binding 1), and a scene of
// one triangle under that ray. Shared by tests/integration/traces_test.cpp and the corpus (tests/corpus).
#include <vulkan/vulkan.h>

#include "history_helpers.h"

namespace asval_test {

// A device with ray-tracing pipelines and push descriptors besides what every test device has (ray queries on
// lavapipe).
vkkit::DeviceOptions RayDevice();

// The same with fragmentStoresAndAtomics, for RayProgram::Kind::kDraw.
vkkit::DeviceOptions RayDrawDevice();

// A compute pipeline with a ray query (ray_query.comp), a ray-tracing pipeline (trace_ray.rgen and
// trace_miss.rmiss, with its shader binding table), or a graphics pipeline whose fragment shader queries the ray
// (draw_ray.vert, draw_ray.frag: one draw into a 1x1 framebuffer without attachments; needs RayDrawDevice()).
// `push`: the set layout is for push descriptors (no set).
class RayProgram {
 public:
  enum class Kind { kRayQuery, kTraceRays, kDraw };
  RayProgram(vkkit::Device& device, Kind kind, bool push = false);
  ~RayProgram();
  RayProgram(const RayProgram&) = delete;
  RayProgram& operator=(const RayProgram&) = delete;

  VkDescriptorSet set() const { return set_; }
  // Writes `structure` into the set's binding 0 (and the output buffer into binding 1).
  void Write(VkAccelerationStructureKHR structure);
  // The same through a descriptor update template (vkUpdateDescriptorSetWithTemplate).
  void WriteWithTemplate(VkAccelerationStructureKHR structure);
  // Binds the pipeline and the set (or pushes `pushed`), and traces or dispatches one ray.
  void Record(VkCommandBuffer cb, VkAccelerationStructureKHR pushed = VK_NULL_HANDLE);
  // Build writes made visible to the ray's reads.
  void BarrierAfterBuild(VkCommandBuffer cb) const;
  // What the last ray wrote (1: it hit); Clear() writes 7.
  uint32_t hit() const { return *static_cast<const uint32_t*>(output_.mapped); }
  void Clear() { *static_cast<uint32_t*>(output_.mapped) = 7; }

 private:
  struct Writes;
  VkPipelineBindPoint bind_point() const {
    if (kind_ == Kind::kDraw) return VK_PIPELINE_BIND_POINT_GRAPHICS;
    return kind_ == Kind::kRayQuery ? VK_PIPELINE_BIND_POINT_COMPUTE : VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR;
  }
  void MakeComputePipeline();
  void MakeRayTracingPipeline();
  void MakeGraphicsPipeline();

  vkkit::Device& device_;
  Kind kind_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  vkkit::Buffer output_;
  vkkit::Buffer sbt_;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;  // kDraw: no attachments
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
  VkStridedDeviceAddressRegionKHR raygen_{}, miss_{};
};

// A device as RayDevice() with VK_EXT_descriptor_buffer (descriptorBuffer), for DescriptorBufferRayQuery.
vkkit::DeviceOptions RayDescriptorBufferDevice();

// The ray-query compute pipeline of RayProgram (ray_query.comp), reading its descriptors from a host-visible
// descriptor buffer (VK_EXT_descriptor_buffer): set 0 at offset 0 of the one buffer bound, binding 0 the structure
// (written with vkGetDescriptorEXT from its address), binding 1 the output buffer.
class DescriptorBufferRayQuery {
 public:
  explicit DescriptorBufferRayQuery(vkkit::Device& device);
  ~DescriptorBufferRayQuery();
  DescriptorBufferRayQuery(const DescriptorBufferRayQuery&) = delete;
  DescriptorBufferRayQuery& operator=(const DescriptorBufferRayQuery&) = delete;

  // Writes the descriptor of the structure at `address` (0: a null descriptor) into binding 0, and the output
  // buffer's into binding 1.
  void Write(VkDeviceAddress address);
  // Writes `value` into every byte of binding 0's descriptor (bytes no vkGetDescriptorEXT made).
  void Scribble(unsigned char value);
  // Binds the pipeline and the descriptor buffer, sets set 0's offset, and dispatches one ray.
  void Record(VkCommandBuffer cb);
  uint32_t hit() const { return *static_cast<const uint32_t*>(output_.mapped); }
  void Clear() { *static_cast<uint32_t*>(output_.mapped) = 7; }

 private:
  vkkit::Device& device_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  vkkit::Buffer descriptors_;
  vkkit::Buffer output_;
  VkDeviceSize structure_offset_ = 0, output_offset_ = 0;
  VkPhysicalDeviceDescriptorBufferPropertiesEXT properties_{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DESCRIPTOR_BUFFER_PROPERTIES_EXT};
};

// A bottom-level structure of one triangle under the ray and a top-level structure with one instance of it.
struct RayScene {
  explicit RayScene(vkkit::Device& d)
      : device(d), inputs(d), blas(d, inputs), tlas(d), instances(tlas.MakeInstances({&blas})) {}
  ~RayScene() { device.Destroy(instances); }
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;
  // Both builds, with the barrier between them.
  void Build(Commands& commands, VkCommandBuffer cb) {
    blas.Build(cb, Shape{});
    commands.Barrier(cb);
    tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  }

  vkkit::Device& device;
  Inputs inputs;
  Blas blas;
  Tlas tlas;
  vkkit::Buffer instances;
};

}  // namespace asval_test
