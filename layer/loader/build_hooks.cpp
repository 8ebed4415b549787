// The acceleration-structure build commands: run the checks, then pass the call down unless the app's
// callback asked to skip it.
#include "build_alignment.h"
#include "layer_data.h"
#include "vk_intercepts.h"

namespace asval::hooks {

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructuresKHR(
    VkCommandBuffer commandBuffer, uint32_t infoCount, const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkAccelerationStructureBuildRangeInfoKHR* const* ppBuildRangeInfos) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx{data->state, *data->reporter, data->instance->settings.enabled_checks};
  const Location loc("vkCmdBuildAccelerationStructuresKHR");
  bool skip = false;
  if (ctx.Enabled(kCheckAlignment)) {
    skip |= ValidateScratchAlignment(ctx, loc, commandBuffer, infoCount, pInfos,
                                     "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710");
  }
  if (skip) return;
  data->dispatch.CmdBuildAccelerationStructuresKHR(commandBuffer, infoCount, pInfos, ppBuildRangeInfos);
}

VKAPI_ATTR void VKAPI_CALL CmdBuildAccelerationStructuresIndirectKHR(
    VkCommandBuffer commandBuffer, uint32_t infoCount, const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkDeviceAddress* pIndirectDeviceAddresses, const uint32_t* pIndirectStrides,
    const uint32_t* const* ppMaxPrimitiveCounts) {
  DeviceData* data = GetDeviceData(commandBuffer);
  const CheckContext ctx{data->state, *data->reporter, data->instance->settings.enabled_checks};
  const Location loc("vkCmdBuildAccelerationStructuresIndirectKHR");
  bool skip = false;
  if (ctx.Enabled(kCheckAlignment)) {
    skip |= ValidateScratchAlignment(ctx, loc, commandBuffer, infoCount, pInfos,
                                     "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03710");
  }
  if (skip) return;
  data->dispatch.CmdBuildAccelerationStructuresIndirectKHR(commandBuffer, infoCount, pInfos, pIndirectDeviceAddresses,
                                                           pIndirectStrides, ppMaxPrimitiveCounts);
}

VKAPI_ATTR VkResult VKAPI_CALL BuildAccelerationStructuresKHR(
    VkDevice device, VkDeferredOperationKHR deferredOperation, uint32_t infoCount,
    const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkAccelerationStructureBuildRangeInfoKHR* const* ppBuildRangeInfos) {
  DeviceData* data = GetDeviceData(device);
  // Host builds have no scratch-alignment rule (scratchData is a host address); their checks come with the
  // record-time checks issue.
  return data->dispatch.BuildAccelerationStructuresKHR(device, deferredOperation, infoCount, pInfos,
                                                       ppBuildRangeInfos);
}

}  // namespace asval::hooks
