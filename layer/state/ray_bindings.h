#pragma once
// Where trace and ray-query work finds its acceleration structures (issue 29, family traces): the shader modules and
// pipelines that read structure descriptors, the descriptor set layouts and update templates that hold them, and the
// structures written into each descriptor set. Written by the hooks of vkCreateShaderModule, the pipeline creations,
// vkCreateDescriptorSetLayout, vkCreateDescriptorUpdateTemplate, vkAllocateDescriptorSets, vkUpdateDescriptorSets
// (and their copies and templates), vkFreeDescriptorSets and the pool resets; read at submission, where each trace
// or dispatch looks its bound sets up (checks/traced_structures.h).
//
// Only objects that hold structures are kept: an app without ray tracing pays one relaxed load per descriptor update
// and pipeline bind. One mutex guards it all: every writer is a creation or a descriptor update, not a recorded
// command.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "concurrent_map.h"
#include "shader_structure_use.h"

namespace asval {

// What a pipeline's stages read structures through (their modules' uses merged; a library's included).
struct PipelineStructureUse {
  ShaderStructureUse use;
  // A stage's code was not seen (a module the layer does not know, a module identifier): bindings may be missing.
  bool partly_unknown = false;
  // Created with VK_PIPELINE_CREATE_DESCRIPTOR_BUFFER_BIT_EXT: its descriptors live in buffers, not sets.
  bool descriptor_buffers = false;
};

// A structure written into a descriptor: the handle and the structure's serial then (AccelerationStructureState::
// serial; 0: the layer did not know it), so that a handle destroyed and reused since is not taken for the same one.
struct DescribedStructure {
  VkAccelerationStructureKHR as = VK_NULL_HANDLE;
  uint64_t serial = 0;
};

// What a lookup of a set's binding found.
enum class SetLookup : uint8_t { kFound, kNotWritten, kUnknown };

class RayBindings {
 public:
  // ---- shader modules and pipelines ----
  // The scan of a module's code (nullopt: not readable).
  void AddModule(VkShaderModule module, const std::optional<ShaderStructureUse>& use);
  void ForgetModule(VkShaderModule module);
  // A module's use; nullopt when the layer does not know the module or could not read it.
  std::optional<ShaderStructureUse> Module(VkShaderModule module) const;
  // Kept only when the pipeline reads structures or may (partly unknown).
  void AddPipeline(VkPipeline pipeline, std::shared_ptr<const PipelineStructureUse> use);
  void ForgetPipeline(VkPipeline pipeline);
  // Null when the pipeline reads no structure the layer knows of. One relaxed load while no pipeline does.
  std::shared_ptr<const PipelineStructureUse> Pipeline(VkPipeline pipeline) const {
    if (!any_pipeline()) return nullptr;
    std::optional<std::shared_ptr<const PipelineStructureUse>> found = pipelines_.find(pipeline);
    return found ? *found : nullptr;
  }
  // Some pipeline reads structures: command buffers track what they bind.
  bool any_pipeline() const { return pipeline_count_.load(std::memory_order_acquire) != 0; }
  // Bumped after every pipeline kept or forgotten: a memo of Pipeline() answers read under an equal stamp is exact.
  StampValue pipelines_stamp() const { return pipelines_.stamp(); }

  // ---- descriptor set layouts, update templates, sets ----
  // A layout's bindings of type VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR (or mutable types that may hold one).
  void AddLayout(const VkDescriptorSetLayoutCreateInfo& info, VkDescriptorSetLayout layout);
  void ForgetLayout(VkDescriptorSetLayout layout);
  void AddTemplate(const VkDescriptorUpdateTemplateCreateInfo& info, VkDescriptorUpdateTemplate update_template);
  void ForgetTemplate(VkDescriptorUpdateTemplate update_template);
  // Sets allocated from `pool` (their handles may be reused ones: what the old set held is forgotten).
  void Allocate(const VkDescriptorSetAllocateInfo& info, const VkDescriptorSet* sets);
  void Free(uint32_t count, const VkDescriptorSet* sets);
  void ResetPool(VkDescriptorPool pool);
  // structure_serial: the serial of a structure now (0: unknown), read outside this class's lock.
  template <typename SerialOf>
  void Update(uint32_t write_count, const VkWriteDescriptorSet* writes, uint32_t copy_count,
              const VkCopyDescriptorSet* copies, SerialOf&& structure_serial);
  template <typename SerialOf>
  void UpdateWithTemplate(VkDescriptorSet set, VkDescriptorUpdateTemplate update_template, const void* data,
                          SerialOf&& structure_serial);
  // Nothing to do for descriptor updates: no layout or template holds structures and no set does.
  bool idle() const { return !tracking_.load(std::memory_order_acquire); }

  // A binding of this type may hold a structure descriptor (the structure type, or a mutable type).
  static bool MayHoldStructures(VkDescriptorType type);

  // ---- descriptor buffers (VK_EXT_descriptor_buffer) ----
  // A descriptor-buffer set layout's structure bindings, each with where its descriptors start in a set's bytes
  // (vkGetDescriptorSetLayoutBindingOffsetEXT, asked by the layer).
  struct BufferBinding {
    uint32_t binding;
    uint32_t count;
    VkDeviceSize offset;
  };
  using BufferBindings = std::vector<BufferBinding>;
  void AddBufferLayout(VkDescriptorSetLayout layout, BufferBindings bindings);
  // Kept only when one of its set layouts is a descriptor-buffer layout with structure bindings.
  void AddPipelineLayout(const VkPipelineLayoutCreateInfo& info, VkPipelineLayout layout);
  void ForgetPipelineLayout(VkPipelineLayout layout);
  // The structure bindings of the descriptor-buffer set layout at `set` of a pipeline layout; null: none known.
  std::shared_ptr<const BufferBindings> BufferBindingsOf(VkPipelineLayout layout, uint32_t set) const;
  // vkGetDescriptorEXT of a structure: the descriptor's bytes, and the structure address they were made from (0: a
  // null descriptor). The bytes are the key: what a shader reads from a descriptor buffer is turned back into an
  // address. At most kMaxDescriptors are kept; past that the oldest are forgotten (then unknown, counted).
  static constexpr std::size_t kMaxDescriptors = 1u << 12;
  void AddStructureDescriptor(const void* bytes, std::size_t size, VkDeviceAddress address);
  // The address the bytes were made from; false when no vkGetDescriptorEXT the layer saw made them.
  bool StructureOfDescriptor(const void* bytes, std::size_t size, VkDeviceAddress* address) const;
  // The size of a structure descriptor (the dataSize of vkGetDescriptorEXT; 0 before any).
  std::size_t structure_descriptor_size() const { return descriptor_size_.load(std::memory_order_acquire); }

  // The structures in `set`'s `binding`, each passed to f(const DescribedStructure&).
  template <typename F>
  SetLookup ForEachIn(VkDescriptorSet set, uint32_t binding, F&& f) const;

  // The structures one write names (VkWriteDescriptorSetAccelerationStructureKHR), with their serials; nullopt when
  // the write's chain holds something else the layer does not read (another way to name structures).
  template <typename SerialOf>
  static std::optional<std::vector<DescribedStructure>> WrittenStructures(const VkWriteDescriptorSet& write,
                                                                          SerialOf&& structure_serial);

  std::size_t set_count() const;

 private:
  // A layout's bindings that may hold structures: binding -> descriptorCount.
  using StructureBindings = std::map<uint32_t, uint32_t>;
  struct SetRecord {
    VkDescriptorPool pool = VK_NULL_HANDLE;
    // The set's layout's structure bindings (a write past a binding's end continues into the next one: only
    // writes that stay in their binding are read). Null: the layout holds none, and the set is unknown.
    std::shared_ptr<const StructureBindings> bindings;
    bool unknown = false;                          // written in a way the layer could not read
    std::map<uint64_t, DescribedStructure> slots;  // (binding << 32 | element) -> structure
  };
  struct TemplateEntry {
    uint32_t binding, element, count;
    std::size_t offset, stride;
  };
  static uint64_t Slot(uint32_t binding, uint32_t element) { return (uint64_t{binding} << 32) | element; }
  void Track() { tracking_.store(true, std::memory_order_release); }
  void WriteStructures(VkDescriptorSet set, uint32_t binding, uint32_t element,
                       const std::vector<DescribedStructure>& structures);
  void MarkUnknown(VkDescriptorSet set);
  void CopyLocked(const VkCopyDescriptorSet& copy);

  mutable std::mutex mutex_;
  std::unordered_map<VkShaderModule, std::optional<ShaderStructureUse>> modules_;
  ConcurrentMap<VkPipeline, std::shared_ptr<const PipelineStructureUse>> pipelines_;
  std::atomic<uint32_t> pipeline_count_{0};
  std::unordered_map<VkDescriptorSetLayout, std::shared_ptr<const StructureBindings>> layouts_;  // only those with any
  std::unordered_map<VkDescriptorUpdateTemplate, std::vector<TemplateEntry>> templates_;  // only those with structures
  std::unordered_map<VkDescriptorSet, SetRecord> sets_;
  std::unordered_map<VkDescriptorSetLayout, std::shared_ptr<const BufferBindings>> buffer_layouts_;
  std::unordered_map<VkPipelineLayout, std::vector<std::shared_ptr<const BufferBindings>>> pipeline_layouts_;
  std::unordered_map<std::string, VkDeviceAddress> descriptors_;  // descriptor bytes -> structure address
  std::vector<std::string> descriptor_order_;                     // insertion order, for forgetting the oldest
  std::size_t descriptor_oldest_ = 0;
  std::atomic<std::size_t> descriptor_size_{0};
  std::atomic<bool> tracking_{false};
};

template <typename SerialOf>
std::optional<std::vector<DescribedStructure>> RayBindings::WrittenStructures(const VkWriteDescriptorSet& write,
                                                                              SerialOf&& structure_serial) {
  const VkWriteDescriptorSetAccelerationStructureKHR* structures = nullptr;
  for (auto* s = static_cast<const VkBaseInStructure*>(write.pNext); s; s = s->pNext) {
    if (s->sType != VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR) return std::nullopt;
    structures = reinterpret_cast<const VkWriteDescriptorSetAccelerationStructureKHR*>(s);
  }
  if (!structures || !structures->pAccelerationStructures) return std::nullopt;
  const uint32_t count = structures->accelerationStructureCount;
  std::vector<DescribedStructure> out(count);
  for (uint32_t i = 0; i < count; ++i) {
    const VkAccelerationStructureKHR as = structures->pAccelerationStructures[i];
    out[i] = DescribedStructure{as, as != VK_NULL_HANDLE ? structure_serial(as) : 0};
  }
  return out;
}

template <typename SerialOf>
void RayBindings::Update(uint32_t write_count, const VkWriteDescriptorSet* writes, uint32_t copy_count,
                         const VkCopyDescriptorSet* copies, SerialOf&& structure_serial) {
  // The serials are read before this class's lock is taken (they come from another map's lock).
  std::vector<std::pair<const VkWriteDescriptorSet*, std::optional<std::vector<DescribedStructure>>>> read;
  for (uint32_t i = 0; writes && i < write_count; ++i) {
    if (writes[i].descriptorType == VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) {
      read.emplace_back(&writes[i], WrittenStructures(writes[i], structure_serial));
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  for (uint32_t i = 0; writes && i < write_count; ++i) {
    // Any other type written over a slot that held a structure (a mutable descriptor) replaces it.
    if (writes[i].descriptorType != VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR) {
      auto set = sets_.find(writes[i].dstSet);
      if (set == sets_.end()) continue;
      for (uint32_t e = 0; e < writes[i].descriptorCount; ++e) {
        set->second.slots.erase(Slot(writes[i].dstBinding, writes[i].dstArrayElement + e));
      }
      continue;
    }
  }
  for (auto& [write, structures] : read) {
    Track();
    if (!structures) {
      MarkUnknown(write->dstSet);
    } else {
      WriteStructures(write->dstSet, write->dstBinding, write->dstArrayElement, *structures);
    }
  }
  for (uint32_t i = 0; copies && i < copy_count; ++i) CopyLocked(copies[i]);
}

template <typename SerialOf>
void RayBindings::UpdateWithTemplate(VkDescriptorSet set, VkDescriptorUpdateTemplate update_template, const void* data,
                                     SerialOf&& structure_serial) {
  std::vector<TemplateEntry> entries;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = templates_.find(update_template);
    if (found == templates_.end()) return;
    entries = found->second;
  }
  std::vector<std::pair<const TemplateEntry*, std::vector<DescribedStructure>>> read;
  for (const TemplateEntry& entry : entries) {
    std::vector<DescribedStructure> structures(entry.count);
    for (uint32_t i = 0; i < entry.count; ++i) {
      VkAccelerationStructureKHR as = VK_NULL_HANDLE;
      std::memcpy(&as, static_cast<const char*>(data) + entry.offset + i * entry.stride, sizeof(as));
      structures[i] = DescribedStructure{as, as != VK_NULL_HANDLE ? structure_serial(as) : 0};
    }
    read.emplace_back(&entry, std::move(structures));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [entry, structures] : read) WriteStructures(set, entry->binding, entry->element, structures);
}

template <typename F>
SetLookup RayBindings::ForEachIn(VkDescriptorSet set, uint32_t binding, F&& f) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto found = sets_.find(set);
  if (found == sets_.end()) return SetLookup::kNotWritten;
  if (found->second.unknown) return SetLookup::kUnknown;
  bool any = false;
  for (auto it = found->second.slots.lower_bound(Slot(binding, 0));
       it != found->second.slots.end() && (it->first >> 32) == binding; ++it) {
    any = true;
    f(it->second);
  }
  return any ? SetLookup::kFound : SetLookup::kNotWritten;
}

}  // namespace asval
