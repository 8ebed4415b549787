#pragma once
// What a command buffer's recording has bound for trace and ray-query work (issue 29, family traces): per bind
// point (compute, ray tracing, graphics), the pipeline when it reads structure descriptors, the descriptor sets bound
// at each set number and the structures pushed there. Written by the recording thread only (CommandBufferState);
// tracked only while some pipeline of the device reads structures (RayBindings::any_pipeline). A trace or dispatch
// turns it into the TracedBinding records of its kTrace operation (MakeTraced).
#include <vulkan/vulkan.h>

#include <array>
#include <memory>
#include <vector>

#include "command_buffer_ops.h"
#include "ray_bindings.h"

namespace asval {

class BoundStructures {
 public:
  enum Point : uint8_t { kCompute, kRayTracing, kGraphics, kPointCount };
  // The point of a bind point the family follows; kPointCount for others (subpass shading, ...).
  static Point PointOf(VkPipelineBindPoint bind_point) {
    if (bind_point == VK_PIPELINE_BIND_POINT_COMPUTE) return kCompute;
    if (bind_point == VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR) return kRayTracing;
    if (bind_point == VK_PIPELINE_BIND_POINT_GRAPHICS) return kGraphics;
    return kPointCount;
  }

  void Reset() {
    for (Bound& b : bound_) {
      b.pipeline.reset();
      b.sets.clear();
      b.pushed.clear();
      b.pushed_sets.clear();
      b.buffer_sets.clear();
    }
    descriptor_buffers_.clear();
  }
  void BindPipeline(Point point, std::shared_ptr<const PipelineStructureUse> pipeline) {
    bound_[point].pipeline = std::move(pipeline);
  }
  void BindSets(Point point, uint32_t first_set, uint32_t count, const VkDescriptorSet* sets);
  // vkCmdPushDescriptorSetKHR: the structures written; `known` false for a push the layer could not read (a
  // template, an unknown chain): that set number is then not followed until bound again.
  void Push(Point point, uint32_t set, uint32_t binding, uint32_t element, const DescribedStructure& structure);
  void PushUnknown(Point point, uint32_t set);
  // Starting a push at `set` replaces what was bound or pushed there before.
  void BeginPush(Point point, uint32_t set);
  // vkCmdBindDescriptorBuffersEXT: the buffers' addresses by index (every bind point reads them).
  void BindDescriptorBuffers(uint32_t count, const VkDescriptorBufferBindingInfoEXT* infos);
  // vkCmdSetDescriptorBufferOffsetsEXT, one set of it: `set` reads buffer `index` at `offset`, laid out as
  // `bindings` (the pipeline layout's set layout there; null: none with structures).
  void SetBufferOffset(Point point, uint32_t set, uint32_t index, VkDeviceSize offset,
                       std::shared_ptr<const RayBindings::BufferBindings> bindings);
  // vkCmdExecuteCommands: the bindings of the primary are undefined afterwards.
  void Forget() { Reset(); }

  // The pipeline bound at `point` when it reads structures (null otherwise).
  const PipelineStructureUse* pipeline(Point point) const { return bound_[point].pipeline.get(); }
  // The traced bindings of a trace (`traces`: a vkCmdTraceRays* command) or dispatch at `point`, appended to out.
  void MakeTraced(Point point, bool traces, std::vector<TracedBinding>& out) const;

 private:
  struct Pushed {
    uint32_t set, binding, element;
    DescribedStructure structure;
  };
  enum class PushState : uint8_t { kNone, kKnown, kUnknown };
  // A set read from a descriptor buffer (vkCmdSetDescriptorBufferOffsetsEXT).
  struct BufferSet {
    bool set = false;
    uint32_t index = 0;
    VkDeviceSize offset = 0;
    // The address bound at `index` when the offset was set: a buffer bound there since makes the set's address one
    // the layer does not assume (read then, or at the command), so the binding is not read.
    VkDeviceAddress base = 0;
    std::shared_ptr<const RayBindings::BufferBindings> bindings;
  };
  struct Bound {
    std::shared_ptr<const PipelineStructureUse> pipeline;
    std::vector<VkDescriptorSet> sets;  // by set number (VK_NULL_HANDLE: none)
    std::vector<Pushed> pushed;
    std::vector<PushState> pushed_sets;  // by set number
    std::vector<BufferSet> buffer_sets;  // by set number
  };
  // The row of a binding a descriptor-buffer pipeline reads.
  TracedBinding BufferRow(const Bound& b, const SetBinding& sb, TracedBy by) const;

  std::array<Bound, kPointCount> bound_;
  std::vector<VkDeviceAddress> descriptor_buffers_;  // by binding index (0: none)
};

}  // namespace asval
