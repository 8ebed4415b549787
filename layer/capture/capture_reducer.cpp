#include "capture_reducer.h"

#include "failure_injection.h"
#include "reduce_inputs.comp.h"

namespace asval {

std::unique_ptr<CaptureReducer> CaptureReducer::Create(VkDevice device, const DeviceDispatchTable& next,
                                                       uint32_t memory_type) {
  if (memory_type == UINT32_MAX || !next.CreateShaderModule || !next.DestroyShaderModule ||
      !next.CreatePipelineLayout || !next.DestroyPipelineLayout || !next.CreateComputePipelines ||
      !next.DestroyPipeline || !next.CmdBindPipeline || !next.CmdDispatchBase || !next.GetBufferDeviceAddress ||
      !next.CreateBuffer || !next.AllocateMemory || !next.MapMemory) {
    return nullptr;
  }
  std::unique_ptr<CaptureReducer> reducer(new CaptureReducer(device, next));
  VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module.codeSize = sizeof(kReduceInputsSpirv);
  module.pCode = kReduceInputsSpirv;
  if (next.CreateShaderModule(device, &module, nullptr, &reducer->module_) != VK_SUCCESS) return nullptr;
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};  // no set, no push constant
  if (next.CreatePipelineLayout(device, &layout, nullptr, &reducer->layout_) != VK_SUCCESS) return nullptr;

  VkBufferCreateInfo table{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  table.size = kReduceSlabs * sizeof(VkDeviceAddress);
  table.usage = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  table.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (next.CreateBuffer(device, &table, nullptr, &reducer->table_) != VK_SUCCESS) return nullptr;
  VkMemoryRequirements requirements{};
  next.GetBufferMemoryRequirements(device, reducer->table_, &requirements);
  if (!(requirements.memoryTypeBits & (1u << memory_type))) return nullptr;
  VkMemoryAllocateFlagsInfo address_flag{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  address_flag.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &address_flag};
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = memory_type;
  void* mapped = nullptr;
  if (next.AllocateMemory(device, &allocate, nullptr, &reducer->table_memory_) != VK_SUCCESS ||
      next.BindBufferMemory(device, reducer->table_, reducer->table_memory_, 0) != VK_SUCCESS ||
      next.MapMemory(device, reducer->table_memory_, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) {
    return nullptr;
  }
  reducer->table_entries_ = static_cast<VkDeviceAddress*>(mapped);
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  address.buffer = reducer->table_;
  reducer->table_address_ = next.GetBufferDeviceAddress(device, &address);
  if (reducer->table_address_ == 0) return nullptr;
  return reducer;
}

CaptureReducer::~CaptureReducer() {
  if (pipeline_) next_.DestroyPipeline(device_, pipeline_, nullptr);
  if (table_) next_.DestroyBuffer(device_, table_, nullptr);
  if (table_memory_) next_.FreeMemory(device_, table_memory_, nullptr);  // unmaps
  if (layout_) next_.DestroyPipelineLayout(device_, layout_, nullptr);
  if (module_) next_.DestroyShaderModule(device_, module_, nullptr);
}

VkPipeline CaptureReducer::Pipeline() {
  std::call_once(compiled_, [this] {
    const uint32_t address[2] = {static_cast<uint32_t>(table_address_), static_cast<uint32_t>(table_address_ >> 32)};
    const VkSpecializationMapEntry entries[2] = {{0, 0, sizeof(uint32_t)}, {1, sizeof(uint32_t), sizeof(uint32_t)}};
    const VkSpecializationInfo specialization{2, entries, sizeof(address), address};
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.flags = VK_PIPELINE_CREATE_DISPATCH_BASE_BIT;
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module_;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = &specialization;
    info.layout = layout_;
    // The test hook: as if vkCreateComputePipelines failed (the captures are then copied).
    if (InjectedFailure(FailSite::kReducePipeline) ||
        next_.CreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_) != VK_SUCCESS) {
      pipeline_ = VK_NULL_HANDLE;
    }
  });
  return pipeline_;
}

uint32_t CaptureReducer::Register(VkDeviceAddress slab) {
  const uint32_t index = slabs_.fetch_add(1, std::memory_order_relaxed);
  if (index >= kReduceSlabs || slab == 0) return UINT32_MAX;
  table_entries_[index] = slab;
  return index;
}

}  // namespace asval
