#pragma once
// The capture reduced on the device (setting capture_method, issue 12): a compute pipeline of the layer's that
// reads a build's vertices, AABBs or instance records where the build reads them and writes one bit per primitive
// (active, undefined input, unreadable) or each instance's reference, so that the host reads a few bytes per
// primitive instead of the geometry and classifies nothing (shaders/reduce_inputs.comp).
//
// The pipeline has an empty layout: the app's descriptor sets and push constants are not touched. Its parameters
// come through the specialization constant (the device address of the capture slab it was made for) and the base
// group of vkCmdDispatchBase (which job of that slab). Binding it replaces the app's compute pipeline, which the
// recorder binds again afterwards (CommandBufferState::compute_pipeline); it is the one piece of app state touched.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>

#include "layer_settings.h"
#include "vk_dispatch_table.h"

namespace asval {

// One job's parameters, as the shader reads them (struct Job of reduce_inputs.comp; 16-aligned in a slab).
struct ReduceJob {
  enum Kind : uint32_t { kTriangles = 0, kAabbs = 1, kInstances = 2 };
  enum XKind : uint32_t { kNoNaN = 0, kFloat32 = 1, kFloat16 = 2 };
  uint32_t kind = kTriangles;
  uint32_t count = 0;         // primitives
  uint32_t stride = 0;        // vertex, AABB or instance record stride
  uint32_t x_kind = kNoNaN;   // triangles: how the vertex format's X can be NaN
  uint32_t components = 3;    // triangles: 2 or 3
  uint32_t index_bytes = 0;   // triangles: 0 (not indexed), 1, 2, 4
  uint32_t first_vertex = 0;  // indexed triangles
  uint32_t max_vertex = 0;    // indexed triangles: the highest vertex that may be read
  uint64_t data = 0;          // vertices (not indexed: the first one read), AABBs or instance records
  uint64_t indices = 0;       // indexed triangles: the first index read
  uint64_t out = 0;           // where the results go (ReducedGeometry, capture_log.h)
  uint64_t unused = 0;
};
static_assert(sizeof(ReduceJob) == 64, "ReduceJob must match reduce_inputs.comp's Job");

// Workgroups of the dispatch: its X groups walk the primitives, 64 per group (beyond 65535 groups, each group
// takes several rounds); Y and Z name the job (16-byte units into its slab, 15 bits in Y, the rest in Z).
inline constexpr uint32_t kReducePrimitivesPerGroup = 64;
inline constexpr uint32_t kReduceMaxGroups = 65535;  // the least maxComputeWorkGroupCount[0] a device has

// Whether a device's capture reduces (capture_method): `auto` on a device that is not a CPU (where the host's
// classification shares the cores with the device's own work anyway, and lavapipe's compute dispatches cost more
// than they save); never without bufferDeviceAddress (the shader reads through device addresses), with shader
// objects enabled (binding a pipeline would unbind the app's compute shader object, which the layer does not
// restore), or with the float_spacing warning (it needs every coordinate on the host).
inline bool CaptureReduces(CaptureMethod method, VkPhysicalDeviceType type, bool buffer_device_address, bool shader_objects,
                           bool float_spacing) {
  if (!buffer_device_address || shader_objects || float_spacing) return false;
  return method == kCaptureMethodReduce || (method == kCaptureMethodAuto && type != VK_PHYSICAL_DEVICE_TYPE_CPU);
}

class CaptureReducer {
 public:
  // The shader module and layout, or null when the device cannot run the pipeline (a command missing).
  static std::unique_ptr<CaptureReducer> Create(VkDevice device, const DeviceDispatchTable& next);
  ~CaptureReducer();
  CaptureReducer(const CaptureReducer&) = delete;
  CaptureReducer& operator=(const CaptureReducer&) = delete;

  // A pipeline reading its jobs from the slab at `slab_address` (made when the slab is); null on failure.
  VkPipeline MakePipeline(VkDeviceAddress slab_address) const;
  void DestroyPipeline(VkPipeline pipeline) const;

 private:
  CaptureReducer(VkDevice device, const DeviceDispatchTable& next) : device_(device), next_(next) {}
  const VkDevice device_;
  const DeviceDispatchTable& next_;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
};

}  // namespace asval
