#include "capture_reducer.h"

#include "reduce_inputs.comp.h"

namespace asval {

std::unique_ptr<CaptureReducer> CaptureReducer::Create(VkDevice device, const DeviceDispatchTable& next) {
  if (!next.CreateShaderModule || !next.DestroyShaderModule || !next.CreatePipelineLayout ||
      !next.DestroyPipelineLayout || !next.CreateComputePipelines || !next.DestroyPipeline || !next.CmdBindPipeline ||
      !next.CmdDispatchBase || !next.GetBufferDeviceAddress) {
    return nullptr;
  }
  std::unique_ptr<CaptureReducer> reducer(new CaptureReducer(device, next));
  VkShaderModuleCreateInfo module{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module.codeSize = sizeof(kReduceInputsSpirv);
  module.pCode = kReduceInputsSpirv;
  if (next.CreateShaderModule(device, &module, nullptr, &reducer->module_) != VK_SUCCESS) return nullptr;
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};  // no set, no push constant
  if (next.CreatePipelineLayout(device, &layout, nullptr, &reducer->layout_) != VK_SUCCESS) return nullptr;
  return reducer;
}

CaptureReducer::~CaptureReducer() {
  if (layout_) next_.DestroyPipelineLayout(device_, layout_, nullptr);
  if (module_) next_.DestroyShaderModule(device_, module_, nullptr);
}

VkPipeline CaptureReducer::MakePipeline(VkDeviceAddress slab_address) const {
  const uint32_t address[2] = {static_cast<uint32_t>(slab_address), static_cast<uint32_t>(slab_address >> 32)};
  const VkSpecializationMapEntry entries[2] = {{0, 0, sizeof(uint32_t)}, {1, sizeof(uint32_t), sizeof(uint32_t)}};
  VkSpecializationInfo specialization{2, entries, sizeof(address), address};
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.flags = VK_PIPELINE_CREATE_DISPATCH_BASE_BIT;
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module_;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = &specialization;
  info.layout = layout_;
  VkPipeline pipeline = VK_NULL_HANDLE;
  if (next_.CreateComputePipelines(device_, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline) != VK_SUCCESS) {
    return VK_NULL_HANDLE;
  }
  return pipeline;
}

void CaptureReducer::DestroyPipeline(VkPipeline pipeline) const {
  if (pipeline) next_.DestroyPipeline(device_, pipeline, nullptr);
}

}  // namespace asval
