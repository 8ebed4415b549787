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

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>

#include "layer_settings.h"
#include "vk_dispatch_table.h"

namespace asval {

// One job's parameters, as the shader reads them (struct Job of reduce_inputs.comp; 16-aligned in a slab).
struct ReduceJob {
  // kGatherInstances: an array of instance pointers at `data` (count of them): the pointers and the records they
  // point to (those FollowedInstancePointer names; zeros for the others) copied to `out` (GatheredBytes).
  enum Kind : uint32_t { kTriangles = 0, kAabbs = 1, kInstances = 2, kGatherInstances = 3 };
  // Or'ed into the kind: an indirect build's geometry, whose range info the shader reads at `range` (the addresses
  // below are then those of a range of offset 0, `count` the most it may have: ppMaxPrimitiveCounts).
  static constexpr uint32_t kIndirect = 256;
  enum XKind : uint32_t { kNoNaN = 0, kFloat32 = 1, kFloat16 = 2 };
  // Triangles: how the vertex format's X can be NaN (XKind), its components (2 or 3) and the index bytes (0: not
  // indexed, 1, 2, 4), in one word.
  static constexpr uint32_t Format(XKind x_kind, uint32_t components, uint32_t index_bytes) {
    return x_kind | components << 8 | index_bytes << 16;
  }
  uint32_t kind = kTriangles;
  uint32_t count = 0;         // primitives
  uint32_t stride = 0;        // vertex, AABB or instance record stride
  uint32_t format = Format(kNoNaN, 3, 0);
  uint32_t first_vertex = 0;  // indexed triangles
  uint32_t max_vertex = 0;    // indexed triangles: the highest vertex that may be read
  uint64_t data = 0;          // vertices (not indexed: the first one read), AABBs or instance records
  uint64_t indices = 0;       // indexed triangles: the first index read
  uint64_t out = 0;           // where the results go (ReducedGeometry, capture_log.h)
  uint64_t transform = 0;     // triangles: the transform, copied after the index hash (0: none, or not captured)
  uint64_t range = 0;         // kIndirect: the geometry's range info
};
static_assert(sizeof(ReduceJob) == 64, "ReduceJob must match reduce_inputs.comp's Job");

// The dispatch: its X groups walk the primitives, 64 per group (beyond 65535 groups, each group takes several
// rounds); each row of Y groups is one job: job = group Y + 32768 * group Z, naming slab job >> 16 of the
// reducer's table and the job 64 * (job & 0xffff) bytes into that slab (vkCmdDispatchBase sets the first).
inline constexpr uint32_t kReducePrimitivesPerGroup = 64;
inline constexpr uint32_t kReduceMaxGroups = 65535;         // the least maxComputeWorkGroupCount a device has
inline constexpr uint32_t kReduceJobsPerSlab = 1u << 16;    // jobs lie in a slab's first 4 MiB
inline constexpr uint32_t kReduceMaxJobsPerDispatch = 32767;  // Y rows, so that base Y + rows <= 65535
inline constexpr uint32_t kReduceSlabs = 4096;              // slabs the table holds (job >> 16 < 16384)

// Whether a device's capture reduces (capture_method): `auto` on a device that is not a CPU (where the host's
// classification shares the cores with the device's own work anyway, and lavapipe's compute dispatches cost more
// than they save); never without bufferDeviceAddress (the shader reads through device addresses), with shader
// objects enabled (binding a pipeline would unbind the app's compute shader object, which the layer does not
// restore), or with the float_spacing warning (it needs every coordinate on the host).
inline bool CaptureReduces(CaptureMethod method, VkPhysicalDeviceType type, bool buffer_device_address,
                           bool shader_objects, bool float_spacing) {
  if (!buffer_device_address || shader_objects || float_spacing) return false;
  return method == kCaptureMethodReduce || (method == kCaptureMethodAuto && type != VK_PHYSICAL_DEVICE_TYPE_CPU);
}

// Whether the layer's dispatch gathers the records of arrays of instance pointers (the second stage of their
// capture: their addresses are on the device, read when the build executes, so no copy recorded beforehand can name
// them), also where the capture copies: with capture_method reduce, or `auto` and `copy` on a device that is not a
// CPU. Not on a CPU device unless asked (lavapipe loses the app's compute state once the layer's pipeline was bound:
// capture.md), nor without bufferDeviceAddress or with shader objects (as CaptureReduces). Where it does not, the
// records are unknown (skipped and counted).
inline bool CaptureGathers(CaptureMethod method, VkPhysicalDeviceType type, bool buffer_device_address,
                           bool shader_objects) {
  if (!buffer_device_address || shader_objects) return false;
  return method == kCaptureMethodReduce || type != VK_PHYSICAL_DEVICE_TYPE_CPU;
}

class CaptureReducer {
 public:
  // The shader module, layout and slab table (in `memory_type`: host-visible and coherent), or null when the
  // device cannot run the pipeline (a command missing, no memory).
  static std::unique_ptr<CaptureReducer> Create(VkDevice device, const DeviceDispatchTable& next,
                                                uint32_t memory_type);
  ~CaptureReducer();
  CaptureReducer(const CaptureReducer&) = delete;
  CaptureReducer& operator=(const CaptureReducer&) = delete;

  // The pipeline, compiled at the first call (the first reduced capture of the device; a driver may take a
  // noticeable time once); null when that failed: the captures are then copied.
  VkPipeline Pipeline();
  // Enters a slab's device address in the table: its index, or UINT32_MAX when the table is full (the slab's
  // captures are then copied).
  uint32_t Register(VkDeviceAddress slab);

 private:
  CaptureReducer(VkDevice device, const DeviceDispatchTable& next) : device_(device), next_(next) {}
  const VkDevice device_;
  const DeviceDispatchTable& next_;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  // The slab table: kReduceSlabs device addresses, host-visible (written when a slab is made, before any
  // submission can read it).
  VkBuffer table_ = VK_NULL_HANDLE;
  VkDeviceMemory table_memory_ = VK_NULL_HANDLE;
  VkDeviceAddress* table_entries_ = nullptr;
  VkDeviceAddress table_address_ = 0;
  std::atomic<uint32_t> slabs_{0};
  std::once_flag compiled_;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

}  // namespace asval
