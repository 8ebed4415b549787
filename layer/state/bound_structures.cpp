#include "bound_structures.h"

#include <utility>

namespace asval {

namespace {

template <typename T>
T& At(std::vector<T>& v, uint32_t i) {
  if (v.size() <= i) v.resize(std::size_t{i} + 1, T{});
  return v[i];
}

TracedBinding Row(const SetBinding& b, TracedSource source, TracedBy by) {
  TracedBinding row;
  row.set_index = b.set;
  row.binding = b.binding;
  row.source = source;
  row.by = by;
  row.set = VK_NULL_HANDLE;
  row.pushed = VK_NULL_HANDLE;
  row.pushed_serial = 0;
  row.descriptor_count = 0;
  row.descriptor_address = 0;
  return row;
}

}  // namespace

void BoundStructures::BindSets(Point point, uint32_t first_set, uint32_t count, const VkDescriptorSet* sets) {
  Bound& b = bound_[point];
  for (uint32_t i = 0; sets && i < count; ++i) {
    At(b.sets, first_set + i) = sets[i];
    if (first_set + i < b.pushed_sets.size()) b.pushed_sets[first_set + i] = PushState::kNone;
    if (first_set + i < b.buffer_sets.size()) b.buffer_sets[first_set + i] = BufferSet{};
  }
}

void BoundStructures::BindDescriptorBuffers(uint32_t count, const VkDescriptorBufferBindingInfoEXT* infos) {
  descriptor_buffers_.assign(count, 0);
  for (uint32_t i = 0; infos && i < count; ++i) descriptor_buffers_[i] = infos[i].address;
}

void BoundStructures::SetBufferOffset(Point point, uint32_t set, uint32_t index, VkDeviceSize offset,
                                      std::shared_ptr<const RayBindings::BufferBindings> bindings) {
  Bound& b = bound_[point];
  const VkDeviceAddress base = index < descriptor_buffers_.size() ? descriptor_buffers_[index] : 0;
  At(b.buffer_sets, set) = BufferSet{true, index, offset, base, std::move(bindings)};
  if (set < b.sets.size()) b.sets[set] = VK_NULL_HANDLE;
  if (set < b.pushed_sets.size()) b.pushed_sets[set] = PushState::kNone;
}

void BoundStructures::BeginPush(Point point, uint32_t set) {
  Bound& b = bound_[point];
  if (set < b.sets.size()) b.sets[set] = VK_NULL_HANDLE;
  PushState& state = At(b.pushed_sets, set);
  if (state != PushState::kNone) {
    std::vector<Pushed>& p = b.pushed;
    std::size_t kept = 0;
    for (const Pushed& entry : p) {
      if (entry.set != set) p[kept++] = entry;
    }
    p.resize(kept);
  }
  state = PushState::kKnown;
}

void BoundStructures::Push(Point point, uint32_t set, uint32_t binding, uint32_t element,
                           const DescribedStructure& structure) {
  Bound& b = bound_[point];
  for (Pushed& entry : b.pushed) {
    if (entry.set == set && entry.binding == binding && entry.element == element) {
      entry.structure = structure;
      return;
    }
  }
  b.pushed.push_back(Pushed{set, binding, element, structure});
}

void BoundStructures::PushUnknown(Point point, uint32_t set) {
  BeginPush(point, set);
  bound_[point].pushed_sets[set] = PushState::kUnknown;
}

TracedBinding BoundStructures::BufferRow(const Bound& b, const SetBinding& sb, TracedBy by) const {
  const BufferSet* set = sb.set < b.buffer_sets.size() && b.buffer_sets[sb.set].set ? &b.buffer_sets[sb.set] : nullptr;
  if (!set || set->index >= descriptor_buffers_.size() || descriptor_buffers_[set->index] == 0) {
    return Row(sb, TracedSource::kNotBound, by);
  }
  // The layout's structure bindings were not known (its offsets could not be asked), or another buffer was bound at
  // that index after the offset was set: the descriptors are not read.
  if (!set->bindings || set->base != descriptor_buffers_[set->index]) return Row(sb, TracedSource::kUnknown, by);
  for (const RayBindings::BufferBinding& binding : *set->bindings) {
    if (binding.binding != sb.binding) continue;
    TracedBinding row = Row(sb, TracedSource::kBuffer, by);
    row.descriptor_address = descriptor_buffers_[set->index] + set->offset + binding.offset;
    row.descriptor_count = binding.count;
    return row;
  }
  return Row(sb, TracedSource::kUnknown, by);
}

void BoundStructures::MakeTraced(Point point, bool traces, std::vector<TracedBinding>& out) const {
  const Bound& b = bound_[point];
  if (!b.pipeline) return;
  const ShaderStructureUse& use = b.pipeline->use;
  // A trace command's pipeline reads its structures through OpTraceRayKHR when it has one; ray queries otherwise.
  const TracedBy by = traces && use.traces ? TracedBy::kTraceRay : TracedBy::kRayQuery;
  for (const SetBinding& sb : use.bindings) {
    const PushState pushed = sb.set < b.pushed_sets.size() ? b.pushed_sets[sb.set] : PushState::kNone;
    if (b.pipeline->descriptor_buffers && pushed == PushState::kNone) {
      out.push_back(BufferRow(b, sb, by));
    } else if (pushed == PushState::kUnknown) {
      out.push_back(Row(sb, TracedSource::kUnknown, by));
    } else if (pushed == PushState::kKnown) {
      bool any = false;
      for (const Pushed& entry : b.pushed) {
        if (entry.set != sb.set || entry.binding != sb.binding) continue;
        TracedBinding row = Row(sb, TracedSource::kPushed, by);
        row.pushed = entry.structure.as;
        row.pushed_serial = entry.structure.serial;
        out.push_back(row);
        any = true;
      }
      if (!any) out.push_back(Row(sb, TracedSource::kNotBound, by));
    } else {
      const VkDescriptorSet set = sb.set < b.sets.size() ? b.sets[sb.set] : VK_NULL_HANDLE;
      TracedBinding row = Row(sb, set != VK_NULL_HANDLE ? TracedSource::kSet : TracedSource::kNotBound, by);
      row.set = set;
      out.push_back(row);
    }
  }
}

}  // namespace asval
