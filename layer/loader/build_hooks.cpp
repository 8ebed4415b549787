// The acceleration-structure build commands: describe the call as a BuildCommand, run the enabled rule
// families over it, then pass the call down unless the app's callback asked to skip it.
#include "build_validation.h"
#include "history_record.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

namespace {

CheckContext MakeCheckContext(const DeviceData& data) {
  return CheckContext{data.state, *data.reporter, data.instance->settings.enabled_checks};
}

}  // namespace

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructuresKHR(
    VkCommandBuffer commandBuffer, uint32_t infoCount, const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkAccelerationStructureBuildRangeInfoKHR* const* ppBuildRangeInfos) {
  DeviceData* data = GetDeviceData(commandBuffer);
  BuildCommand cmd{BuildCommandKind::kCmdBuild, "vkCmdBuildAccelerationStructuresKHR"};
  cmd.device = data->device;
  cmd.command_buffer = commandBuffer;
  cmd.info_count = infoCount;
  cmd.infos = pInfos;
  cmd.ranges = ppBuildRangeInfos;
  if (ValidateBuildCommand(MakeCheckContext(*data), cmd)) return;
  data->dispatch.CmdBuildAccelerationStructuresKHR(commandBuffer, infoCount, pInfos, ppBuildRangeInfos);
  RecordDeviceBuild(data->state, data->instance->settings.enabled_checks, cmd);  // history: applied at submission
}

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructuresIndirectKHR(
    VkCommandBuffer commandBuffer, uint32_t infoCount, const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkDeviceAddress* pIndirectDeviceAddresses, const uint32_t* pIndirectStrides,
    const uint32_t* const* ppMaxPrimitiveCounts) {
  DeviceData* data = GetDeviceData(commandBuffer);
  BuildCommand cmd{BuildCommandKind::kCmdBuildIndirect, "vkCmdBuildAccelerationStructuresIndirectKHR"};
  cmd.device = data->device;
  cmd.command_buffer = commandBuffer;
  cmd.info_count = infoCount;
  cmd.infos = pInfos;
  cmd.indirect_addresses = pIndirectDeviceAddresses;
  cmd.indirect_strides = pIndirectStrides;
  cmd.max_primitive_counts = ppMaxPrimitiveCounts;
  if (ValidateBuildCommand(MakeCheckContext(*data), cmd)) return;
  data->dispatch.CmdBuildAccelerationStructuresIndirectKHR(commandBuffer, infoCount, pInfos, pIndirectDeviceAddresses,
                                                           pIndirectStrides, ppMaxPrimitiveCounts);
  RecordDeviceBuild(data->state, data->instance->settings.enabled_checks, cmd);  // history: applied at submission
}

VKAPI_ATTR VkResult VKAPI_CALL BuildAccelerationStructuresKHR(
    VkDevice device, VkDeferredOperationKHR deferredOperation, uint32_t infoCount,
    const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkAccelerationStructureBuildRangeInfoKHR* const* ppBuildRangeInfos) {
  DeviceData* data = GetDeviceData(device);
  BuildCommand cmd{BuildCommandKind::kHostBuild, "vkBuildAccelerationStructuresKHR"};
  cmd.device = device;
  cmd.deferred_operation = deferredOperation;
  cmd.info_count = infoCount;
  cmd.infos = pInfos;
  cmd.ranges = ppBuildRangeInfos;
  // Skipped by the app's callback: the build did not happen. VK_ERROR_VALIDATION_FAILED_EXT is what the
  // Khronos layer returns in that case.
  if (ValidateBuildCommand(MakeCheckContext(*data), cmd)) return VK_ERROR_VALIDATION_FAILED_EXT;
  const VkResult result =
      data->dispatch.BuildAccelerationStructuresKHR(device, deferredOperation, infoCount, pInfos, ppBuildRangeInfos);
  // History: applied now on success, or when the deferred operation completes.
  FinishHostBuild(data->state, data->instance->settings.enabled_checks, cmd, result);
  return result;
}

}  // namespace asval::hooks
