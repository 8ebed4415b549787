#include "ray_bindings.h"

namespace asval {

bool RayBindings::MayHoldStructures(VkDescriptorType type) {
  return type == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR || type == VK_DESCRIPTOR_TYPE_MUTABLE_EXT;
}

void RayBindings::AddModule(VkShaderModule module, const std::optional<ShaderStructureUse>& use) {
  std::lock_guard<std::mutex> lock(mutex_);
  modules_[module] = use;
}

void RayBindings::ForgetModule(VkShaderModule module) {
  std::lock_guard<std::mutex> lock(mutex_);
  modules_.erase(module);
}

std::optional<ShaderStructureUse> RayBindings::Module(VkShaderModule module) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = modules_.find(module);
  return found == modules_.end() ? std::nullopt : found->second;
}

void RayBindings::AddPipeline(VkPipeline pipeline, std::shared_ptr<const PipelineStructureUse> use) {
  if (pipelines_.insert_or_assign(pipeline, std::move(use))) pipeline_count_.fetch_add(1, std::memory_order_acq_rel);
}

void RayBindings::ForgetPipeline(VkPipeline pipeline) {
  if (!any_pipeline()) return;
  if (pipelines_.erase(pipeline)) pipeline_count_.fetch_sub(1, std::memory_order_acq_rel);
}

void RayBindings::AddLayout(const VkDescriptorSetLayoutCreateInfo& info, VkDescriptorSetLayout layout) {
  auto bindings = std::make_shared<StructureBindings>();
  for (uint32_t i = 0; info.pBindings && i < info.bindingCount; ++i) {
    const VkDescriptorSetLayoutBinding& b = info.pBindings[i];
    if (MayHoldStructures(b.descriptorType)) (*bindings)[b.binding] = b.descriptorCount;
  }
  if (bindings->empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  layouts_[layout] = std::move(bindings);
  Track();
}

void RayBindings::ForgetLayout(VkDescriptorSetLayout layout) {
  if (idle()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  layouts_.erase(layout);
  buffer_layouts_.erase(layout);
}

void RayBindings::AddBufferLayout(VkDescriptorSetLayout layout, BufferBindings bindings) {
  if (bindings.empty()) return;
  auto shared = std::make_shared<const BufferBindings>(std::move(bindings));
  std::lock_guard<std::mutex> lock(mutex_);
  buffer_layouts_[layout] = std::move(shared);
  Track();
}

void RayBindings::AddPipelineLayout(const VkPipelineLayoutCreateInfo& info, VkPipelineLayout layout) {
  if (idle() || !info.pSetLayouts) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (buffer_layouts_.empty()) return;
  std::vector<std::shared_ptr<const BufferBindings>> sets(info.setLayoutCount);
  bool any = false;
  for (uint32_t i = 0; i < info.setLayoutCount; ++i) {
    const auto found = buffer_layouts_.find(info.pSetLayouts[i]);
    if (found == buffer_layouts_.end()) continue;
    sets[i] = found->second;
    any = true;
  }
  if (any) pipeline_layouts_[layout] = std::move(sets);
}

void RayBindings::ForgetPipelineLayout(VkPipelineLayout layout) {
  if (idle()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  pipeline_layouts_.erase(layout);
}

std::shared_ptr<const RayBindings::BufferBindings> RayBindings::BufferBindingsOf(VkPipelineLayout layout,
                                                                                 uint32_t set) const {
  if (idle()) return nullptr;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = pipeline_layouts_.find(layout);
  if (found == pipeline_layouts_.end() || set >= found->second.size()) return nullptr;
  return found->second[set];
}

void RayBindings::AddStructureDescriptor(const void* bytes, std::size_t size, VkDeviceAddress address) {
  if (!bytes || size == 0) return;
  std::string key(static_cast<const char*>(bytes), size);
  std::lock_guard<std::mutex> lock(mutex_);
  descriptor_size_.store(size, std::memory_order_release);
  const auto [it, inserted] = descriptors_.insert_or_assign(key, address);
  if (!inserted) return;
  // The oldest descriptor goes once the limit is reached (a ring over insertion order).
  if (descriptor_order_.size() < kMaxDescriptors) {
    descriptor_order_.push_back(std::move(key));
  } else {
    descriptors_.erase(descriptor_order_[descriptor_oldest_]);
    descriptor_order_[descriptor_oldest_] = std::move(key);
    descriptor_oldest_ = (descriptor_oldest_ + 1) % kMaxDescriptors;
  }
  Track();
}

bool RayBindings::StructureOfDescriptor(const void* bytes, std::size_t size, VkDeviceAddress* address) const {
  const std::string key(static_cast<const char*>(bytes), size);
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = descriptors_.find(key);
  if (found == descriptors_.end()) return false;
  *address = found->second;
  return true;
}

void RayBindings::AddTemplate(const VkDescriptorUpdateTemplateCreateInfo& info,
                              VkDescriptorUpdateTemplate update_template) {
  if (info.templateType != VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_DESCRIPTOR_SET) return;  // push templates: per command
  std::vector<TemplateEntry> entries;
  for (uint32_t i = 0; info.pDescriptorUpdateEntries && i < info.descriptorUpdateEntryCount; ++i) {
    const VkDescriptorUpdateTemplateEntry& e = info.pDescriptorUpdateEntries[i];
    if (e.descriptorType != VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) continue;
    entries.push_back(TemplateEntry{e.dstBinding, e.dstArrayElement, e.descriptorCount, e.offset, e.stride});
  }
  if (entries.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  templates_[update_template] = std::move(entries);
  Track();
}

void RayBindings::ForgetTemplate(VkDescriptorUpdateTemplate update_template) {
  if (idle()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  templates_.erase(update_template);
}

void RayBindings::Allocate(const VkDescriptorSetAllocateInfo& info, const VkDescriptorSet* sets) {
  if (idle() || !sets) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (uint32_t i = 0; info.pSetLayouts && i < info.descriptorSetCount; ++i) {
    sets_.erase(sets[i]);  // a reused handle: the old set is gone
    const auto layout = layouts_.find(info.pSetLayouts[i]);
    if (layout == layouts_.end()) continue;
    SetRecord& record = sets_[sets[i]];
    record.pool = info.descriptorPool;
    record.bindings = layout->second;
  }
}

void RayBindings::Free(uint32_t count, const VkDescriptorSet* sets) {
  if (idle() || !sets) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (uint32_t i = 0; i < count; ++i) sets_.erase(sets[i]);
}

void RayBindings::ResetPool(VkDescriptorPool pool) {
  if (idle()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto it = sets_.begin(); it != sets_.end();) {
    it = it->second.pool == pool ? sets_.erase(it) : std::next(it);
  }
}

void RayBindings::WriteStructures(VkDescriptorSet set, uint32_t binding, uint32_t element,
                                  const std::vector<DescribedStructure>& structures) {
  SetRecord& record = sets_[set];
  if (!record.bindings) return MarkUnknown(set);  // a set the layer saw allocated with no structure binding
  const auto count = record.bindings->find(binding);
  if (count == record.bindings->end() || element + uint64_t{structures.size()} > count->second) {
    return MarkUnknown(set);  // continues into the next binding: not followed
  }
  for (std::size_t i = 0; i < structures.size(); ++i) {
    record.slots[Slot(binding, element + static_cast<uint32_t>(i))] = structures[i];
  }
}

void RayBindings::MarkUnknown(VkDescriptorSet set) {
  SetRecord& record = sets_[set];
  record.unknown = true;
  record.slots.clear();
}

void RayBindings::CopyLocked(const VkCopyDescriptorSet& copy) {
  const auto src = sets_.find(copy.srcSet);
  const auto dst = sets_.find(copy.dstSet);
  if (src == sets_.end() && dst == sets_.end()) return;  // neither holds structures
  if (dst != sets_.end() && dst->second.bindings && !dst->second.bindings->count(copy.dstBinding))
    return;  // another type
  if (src == sets_.end() || src->second.unknown) return MarkUnknown(copy.dstSet);
  std::vector<DescribedStructure> structures(copy.descriptorCount);
  for (uint32_t i = 0; i < copy.descriptorCount; ++i) {
    const auto slot = src->second.slots.find(Slot(copy.srcBinding, copy.srcArrayElement + i));
    if (slot != src->second.slots.end()) structures[i] = slot->second;
  }
  WriteStructures(copy.dstSet, copy.dstBinding, copy.dstArrayElement, structures);
}

std::size_t RayBindings::set_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return sets_.size();
}

}  // namespace asval
