#include "ray_recorder.h"

#include <array>
#include <cstdint>
#include <new>

#include "history_recorder.h"

namespace asval {

namespace {

// The serial of a live structure (0: the layer does not know it).
uint64_t SerialOf(const DeviceState& state, VkAccelerationStructureKHR as) {
  const std::optional<std::shared_ptr<const AccelerationStructureState>> found = state.acceleration_structures.find(as);
  return found && *found ? (*found)->serial : 0;
}

// What one pipeline stage reads: its module's scan, or the code chained in its create info (a module created with
// the pipeline); nullopt when neither is known (a module identifier, a module the layer never saw).
std::optional<ShaderStructureUse> StageUse(const DeviceState& state, const VkPipelineShaderStageCreateInfo& stage) {
  if (stage.module != VK_NULL_HANDLE) return state.ray_bindings.Module(stage.module);
  for (auto* s = static_cast<const VkBaseInStructure*>(stage.pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO) {
      const auto* code = reinterpret_cast<const VkShaderModuleCreateInfo*>(s);
      return ScanShaderStructureUse(code->pCode, code->codeSize / sizeof(uint32_t));
    }
  }
  return std::nullopt;
}

void MergeStage(const DeviceState& state, const VkPipelineShaderStageCreateInfo& stage, PipelineStructureUse& use) {
  const std::optional<ShaderStructureUse> scanned = StageUse(state, stage);
  if (scanned) {
    use.use.Merge(*scanned);
  } else {
    use.partly_unknown = true;
  }
}

// Libraries linked into a pipeline are pipelines created through this layer: their uses were kept (none kept: they
// read none).
void MergeLibraries(const DeviceState& state, const VkPipelineLibraryCreateInfoKHR& libraries,
                    PipelineStructureUse& use) {
  for (uint32_t l = 0; libraries.pLibraries && l < libraries.libraryCount; ++l) {
    if (auto library = state.ray_bindings.Pipeline(libraries.pLibraries[l])) {
      use.use.Merge(library->use);
      use.partly_unknown |= library->partly_unknown;
    }
  }
}

void Keep(DeviceState& state, VkPipeline pipeline, PipelineStructureUse use, VkPipelineCreateFlags flags) {
  if (pipeline == VK_NULL_HANDLE || !use.use.uses_structures()) return;
  use.descriptor_buffers = (flags & VK_PIPELINE_CREATE_DESCRIPTOR_BUFFER_BIT_EXT) != 0;
  state.ray_bindings.AddPipeline(pipeline, std::make_shared<const PipelineStructureUse>(std::move(use)));
}

// The recording of cb while traces are followed and some pipeline reads structures; null otherwise. Through the
// thread's memo of the last command buffer it looked up (LastRecordedBuild, history_recorder.h: valid while the
// command-buffer map's stamp reads the same, and for the call): binds and draws come by the thousand per frame, and
// a map lookup each would cost more than the rest of the hook.
CommandBufferState* Following(DeviceState& state, VkCommandBuffer cb) {
  if (!state.traces_tracked || !state.ray_bindings.any_pipeline()) return nullptr;
  thread_local LastRecordedBuild last;
  const StampValue stamp = state.command_buffers.stamp();
  if (last.cb != cb || last.stamp != stamp) last = LastRecordedBuild{stamp, cb, state.command_buffers.Find(cb).get()};
  return last.state;
}

// What a bound pipeline reads (null: no structure). Binds come by the thousand per frame: through the thread's small
// table of the pipelines it looked up, each with the stamp of the map of pipelines that read structures when it was
// looked up (read before the lookup, so a pipeline kept or forgotten meanwhile makes the entry stale, never wrong).
std::shared_ptr<const PipelineStructureUse> PipelineUse(const DeviceState& state, VkPipeline pipeline) {
  struct Entry {
    StampValue stamp;
    VkPipeline pipeline = VK_NULL_HANDLE;
    std::shared_ptr<const PipelineStructureUse> use;
  };
  constexpr unsigned kBits = 6;
  thread_local std::array<Entry, 1u << kBits> memo;
  const StampValue stamp = state.ray_bindings.pipelines_stamp();
  Entry& e = memo[(reinterpret_cast<uint64_t>(pipeline) * 0x9e3779b97f4a7c15ull) >> (64 - kBits)];
  if (e.pipeline != pipeline || e.stamp != stamp) e = Entry{stamp, pipeline, state.ray_bindings.Pipeline(pipeline)};
  return e.use;
}

// The bind point whose pipeline a trace, dispatch or draw runs.
BoundStructures::Point PointOfCommand(OpCommand command) {
  switch (command) {
    case OpCommand::kCmdTraceRays:
    case OpCommand::kCmdTraceRaysIndirect:
    case OpCommand::kCmdTraceRaysIndirect2:
      return BoundStructures::kRayTracing;
    case OpCommand::kCmdDispatch:
    case OpCommand::kCmdDispatchIndirect:
    case OpCommand::kCmdDispatchBase:
      return BoundStructures::kCompute;
    default:
      return BoundStructures::kGraphics;
  }
}

// The object creations and descriptor updates allocate; a failure leaves the object unfollowed (its traces are
// then not judged: a set never written is skipped, a pipeline not kept is not followed), counted.
template <typename F>
void Guarded(const DeviceState& state, F&& write) {
  try {
    write();
  } catch (const std::bad_alloc&) {
    state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace

void RecordCreateShaderModule(DeviceState& state, const VkShaderModuleCreateInfo& info, VkShaderModule module) {
  if (!state.traces_tracked) return;
  Guarded(state, [&] {
    state.ray_bindings.AddModule(module, ScanShaderStructureUse(info.pCode, info.codeSize / sizeof(uint32_t)));
  });
}

void RecordDestroyShaderModule(DeviceState& state, VkShaderModule module) {
  if (state.traces_tracked && module != VK_NULL_HANDLE) state.ray_bindings.ForgetModule(module);
}

void RecordCreateComputePipelines(DeviceState& state, uint32_t count, const VkComputePipelineCreateInfo* infos,
                                  const VkPipeline* pipelines) {
  if (!state.traces_tracked || !infos || !pipelines) return;
  Guarded(state, [&] {
    for (uint32_t i = 0; i < count; ++i) {
      PipelineStructureUse use;
      MergeStage(state, infos[i].stage, use);
      Keep(state, pipelines[i], std::move(use), infos[i].flags);
    }
  });
}

void RecordCreateRayTracingPipelines(DeviceState& state, uint32_t count, const VkRayTracingPipelineCreateInfoKHR* infos,
                                     const VkPipeline* pipelines) {
  if (!state.traces_tracked || !infos || !pipelines) return;
  Guarded(state, [&] {
    for (uint32_t i = 0; i < count; ++i) {
      const VkRayTracingPipelineCreateInfoKHR& info = infos[i];
      PipelineStructureUse use;
      for (uint32_t s = 0; info.pStages && s < info.stageCount; ++s) MergeStage(state, info.pStages[s], use);
      if (info.pLibraryInfo) MergeLibraries(state, *info.pLibraryInfo, use);
      Keep(state, pipelines[i], std::move(use), info.flags);
    }
  });
}

void RecordCreateGraphicsPipelines(DeviceState& state, uint32_t count, const VkGraphicsPipelineCreateInfo* infos,
                                   const VkPipeline* pipelines) {
  if (!state.traces_tracked || !infos || !pipelines) return;
  Guarded(state, [&] {
    for (uint32_t i = 0; i < count; ++i) {
      const VkGraphicsPipelineCreateInfo& info = infos[i];
      PipelineStructureUse use;
      for (uint32_t s = 0; info.pStages && s < info.stageCount; ++s) MergeStage(state, info.pStages[s], use);
      // Graphics pipeline libraries (VK_EXT_graphics_pipeline_library) linked into it, chained.
      for (auto* s = static_cast<const VkBaseInStructure*>(info.pNext); s; s = s->pNext) {
        if (s->sType == VK_STRUCTURE_TYPE_PIPELINE_LIBRARY_CREATE_INFO_KHR) {
          MergeLibraries(state, *reinterpret_cast<const VkPipelineLibraryCreateInfoKHR*>(s), use);
        }
      }
      Keep(state, pipelines[i], std::move(use), info.flags);
    }
  });
}

void RecordDestroyPipeline(DeviceState& state, VkPipeline pipeline) {
  if (state.traces_tracked && pipeline != VK_NULL_HANDLE) state.ray_bindings.ForgetPipeline(pipeline);
}

void RecordCreateDescriptorSetLayout(DeviceState& state, const VkDescriptorSetLayoutCreateInfo& info,
                                     VkDescriptorSetLayout layout,
                                     const std::function<VkDeviceSize(uint32_t binding)>& offset_of) {
  if (!state.traces_tracked) return;
  Guarded(state, [&] {
    state.ray_bindings.AddLayout(info, layout);
    if (!(info.flags & VK_DESCRIPTOR_SET_LAYOUT_CREATE_DESCRIPTOR_BUFFER_BIT_EXT) || !offset_of) return;
    RayBindings::BufferBindings bindings;
    for (uint32_t i = 0; info.pBindings && i < info.bindingCount; ++i) {
      const VkDescriptorSetLayoutBinding& b = info.pBindings[i];
      if (!RayBindings::MayHoldStructures(b.descriptorType)) continue;
      bindings.push_back(RayBindings::BufferBinding{b.binding, b.descriptorCount, offset_of(b.binding)});
    }
    state.ray_bindings.AddBufferLayout(layout, std::move(bindings));
  });
}

void RecordCreatePipelineLayout(DeviceState& state, const VkPipelineLayoutCreateInfo& info, VkPipelineLayout layout) {
  if (state.traces_tracked) Guarded(state, [&] { state.ray_bindings.AddPipelineLayout(info, layout); });
}

void RecordDestroyPipelineLayout(DeviceState& state, VkPipelineLayout layout) {
  if (state.traces_tracked && layout != VK_NULL_HANDLE) state.ray_bindings.ForgetPipelineLayout(layout);
}

void RecordGetDescriptor(DeviceState& state, const VkDescriptorGetInfoEXT& info, std::size_t size, const void* bytes) {
  if (!state.traces_tracked || info.type != VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) return;
  Guarded(state, [&] { state.ray_bindings.AddStructureDescriptor(bytes, size, info.data.accelerationStructure); });
}

void RecordDestroyDescriptorSetLayout(DeviceState& state, VkDescriptorSetLayout layout) {
  if (state.traces_tracked && layout != VK_NULL_HANDLE) state.ray_bindings.ForgetLayout(layout);
}

void RecordCreateDescriptorUpdateTemplate(DeviceState& state, const VkDescriptorUpdateTemplateCreateInfo& info,
                                          VkDescriptorUpdateTemplate update_template) {
  if (state.traces_tracked) Guarded(state, [&] { state.ray_bindings.AddTemplate(info, update_template); });
}

void RecordDestroyDescriptorUpdateTemplate(DeviceState& state, VkDescriptorUpdateTemplate update_template) {
  if (state.traces_tracked && update_template != VK_NULL_HANDLE) state.ray_bindings.ForgetTemplate(update_template);
}

void RecordAllocateDescriptorSets(DeviceState& state, const VkDescriptorSetAllocateInfo& info,
                                  const VkDescriptorSet* sets) {
  if (!state.traces_tracked || state.ray_bindings.idle()) return;
  Guarded(state, [&] { state.ray_bindings.Allocate(info, sets); });
}

void RecordFreeDescriptorSets(DeviceState& state, uint32_t count, const VkDescriptorSet* sets) {
  if (state.traces_tracked) state.ray_bindings.Free(count, sets);
}

void RecordResetDescriptorPool(DeviceState& state, VkDescriptorPool pool) {
  if (state.traces_tracked) state.ray_bindings.ResetPool(pool);
}

void RecordUpdateDescriptorSets(DeviceState& state, uint32_t write_count, const VkWriteDescriptorSet* writes,
                                uint32_t copy_count, const VkCopyDescriptorSet* copies) {
  if (!state.traces_tracked || state.ray_bindings.idle()) return;
  Guarded(state, [&] {
    state.ray_bindings.Update(write_count, writes, copy_count, copies,
                              [&](VkAccelerationStructureKHR as) { return SerialOf(state, as); });
  });
}

void RecordUpdateDescriptorSetWithTemplate(DeviceState& state, VkDescriptorSet set,
                                           VkDescriptorUpdateTemplate update_template, const void* data) {
  if (!state.traces_tracked || state.ray_bindings.idle() || !data) return;
  Guarded(state, [&] {
    state.ray_bindings.UpdateWithTemplate(set, update_template, data,
                                          [&](VkAccelerationStructureKHR as) { return SerialOf(state, as); });
  });
}

void RecordBindPipelineForTraces(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point,
                                 VkPipeline pipeline) {
  const BoundStructures::Point point = BoundStructures::PointOf(bind_point);
  if (point == BoundStructures::kPointCount) return;
  if (CommandBufferState* recording = Following(state, cb)) {
    recording->bound_structures.BindPipeline(point, PipelineUse(state, pipeline));
  }
}

void RecordBindDescriptorSets(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point,
                              uint32_t first_set, uint32_t count, const VkDescriptorSet* sets) {
  const BoundStructures::Point point = BoundStructures::PointOf(bind_point);
  if (point == BoundStructures::kPointCount) return;
  if (CommandBufferState* recording = Following(state, cb)) {
    Guarded(state, [&] { recording->bound_structures.BindSets(point, first_set, count, sets); });
  }
}

void RecordPushDescriptorSet(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point, uint32_t set,
                             uint32_t write_count, const VkWriteDescriptorSet* writes) {
  const BoundStructures::Point point = BoundStructures::PointOf(bind_point);
  if (point == BoundStructures::kPointCount) return;
  CommandBufferState* recording = Following(state, cb);
  if (!recording) return;
  BoundStructures& bound = recording->bound_structures;
  Guarded(state, [&] {
    bound.BeginPush(point, set);
    for (uint32_t i = 0; writes && i < write_count; ++i) {
      if (writes[i].descriptorType != VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) continue;
      const std::optional<std::vector<DescribedStructure>> structures =
          RayBindings::WrittenStructures(writes[i], [&](VkAccelerationStructureKHR as) { return SerialOf(state, as); });
      if (!structures) return bound.PushUnknown(point, set);
      for (std::size_t e = 0; e < structures->size(); ++e) {
        bound.Push(point, set, writes[i].dstBinding, writes[i].dstArrayElement + static_cast<uint32_t>(e),
                   (*structures)[e]);
      }
    }
  });
}

void RecordPushDescriptorSetWithTemplate(DeviceState& state, VkCommandBuffer cb, uint32_t set) {
  if (CommandBufferState* recording = Following(state, cb)) {
    Guarded(state, [&] {
      for (uint8_t point = 0; point < BoundStructures::kPointCount; ++point) {
        recording->bound_structures.PushUnknown(static_cast<BoundStructures::Point>(point), set);
      }
    });
  }
}

void RecordBindDescriptorBuffers(DeviceState& state, VkCommandBuffer cb, uint32_t count,
                                 const VkDescriptorBufferBindingInfoEXT* infos) {
  if (CommandBufferState* recording = Following(state, cb)) {
    Guarded(state, [&] { recording->bound_structures.BindDescriptorBuffers(count, infos); });
  }
}

void RecordSetDescriptorBufferOffsets(DeviceState& state, VkCommandBuffer cb, VkPipelineBindPoint bind_point,
                                      VkPipelineLayout layout, uint32_t first_set, uint32_t count,
                                      const uint32_t* indices, const VkDeviceSize* offsets) {
  const BoundStructures::Point point = BoundStructures::PointOf(bind_point);
  if (point == BoundStructures::kPointCount) return;
  CommandBufferState* recording = Following(state, cb);
  if (!recording) return;
  if (!indices || !offsets) return;
  Guarded(state, [&] {
    for (uint32_t i = 0; i < count; ++i) {
      recording->bound_structures.SetBufferOffset(point, first_set + i, indices[i], offsets[i],
                                                  state.ray_bindings.BufferBindingsOf(layout, first_set + i));
    }
  });
}

void RecordExecuteForTraces(DeviceState& state, VkCommandBuffer primary) {
  if (CommandBufferState* recording = Following(state, primary)) {
    recording->bound_structures.Forget();
  }
}

void RecordTraceCommand(DeviceState& state, VkCommandBuffer cb, OpCommand command) {
  CommandBufferState* recording = Following(state, cb);
  if (!recording) return;
  const BoundStructures::Point point = PointOfCommand(command);
  if (!recording->bound_structures.pipeline(point)) return;  // most draws: their pipeline reads no structure
  const bool traces = point == BoundStructures::kRayTracing;
  thread_local std::vector<TracedBinding> traced;
  traced.clear();
  try {
    recording->bound_structures.MakeTraced(point, traces, traced);
    OpOrigin origin;
    origin.command = command;
    origin.ordinal = recording->NextOrdinal(command);
    origin.command_buffer = cb;
    recording->recording.AppendTrace(origin, traced.data(), static_cast<uint32_t>(traced.size()));
  } catch (const std::bad_alloc&) {
    // The trace is not judged; the recording's history stays exact (a trace changes no structure).
    state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
  }
}

}  // namespace asval
