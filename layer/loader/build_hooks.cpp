// The acceleration-structure build commands: describe the call as a BuildCommand, run the enabled rule
// families over it (validate), pass the call down unless the app's callback asked to skip it, then record
// what it does to the structures' histories (post-record).
#include "build_validation.h"
#include "capture_notices.h"
#include "check_thread_data.h"
#include "history_recorder.h"
#include "host_capture.h"
#include "layer_data.h"
#include "vk_intercepts.h"
#include "withhold.h"

namespace asval::hooks {

namespace {

// Pre-record: the captures of what the infos that need it read, planned into the command buffer's run of build
// commands and recorded where the run ends (layer/capture, capture_run.h). Returns
// per info its capture index plus one (0: none), or null when the call captures nothing: the common static
// build costs one flag test per info.
const uint32_t* PreRecordCapture(DeviceData& data, VkCommandBuffer cb, uint32_t info_count,
                                 const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                                 const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                                 std::vector<uint32_t>& captured) {
  // Null arrays break implicit rules asval leaves to the Khronos layer; the capture must not read them either.
  if (!data.capture_tracker || !infos || !ranges) return nullptr;
  bool any = false;
  for (uint32_t i = 0; i < info_count && !any; ++i) any = NeedsCapture(data.instance->settings.capture, infos[i]);
  if (!any) return nullptr;
  const std::shared_ptr<CommandBufferState> recording = data.state.command_buffers.Find(cb);
  if (!recording) return nullptr;  // a command buffer the layer never saw: its submission makes history unknown
  const bool any_captured =
      CaptureBuildInputs(MakeCaptureContext(data), cb, *recording, info_count, infos, ranges, captured);
  ReportCaptureBudget(MakeCheckContext(data), data.instance->settings.capture_budget_mb,
                      "vkCmdBuildAccelerationStructuresKHR");
  return any_captured ? captured.data() : nullptr;
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
  const CheckThreadLease thread;  // the call's one thread_local access, for the checks and the recorder
  const ProtectScope protect(data->reporter->protects());
  if (ValidateBuildCommand(MakeCheckContext(*data), cmd, thread.data())) {
    return WithholdRecordedCommand(*data, cmd.function, commandBuffer, protect);
  }
  const uint32_t* captured = PreRecordCapture(*data, commandBuffer, infoCount, pInfos, ppBuildRangeInfos,
                                              thread.data().captured_infos);
  data->dispatch.CmdBuildAccelerationStructuresKHR(commandBuffer, infoCount, pInfos, ppBuildRangeInfos);
  RecordCmdBuild(data->state, commandBuffer, OpCommand::kCmdBuild, infoCount, pInfos, ppBuildRangeInfos,
                 &thread.data().last_recorded, captured);
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
  const CheckThreadLease thread;  // the call's one thread_local access, for the checks and the recorder
  const ProtectScope protect(data->reporter->protects());
  if (ValidateBuildCommand(MakeCheckContext(*data), cmd, thread.data())) {
    return WithholdRecordedCommand(*data, cmd.function, commandBuffer, protect);
  }
  // Pre-record: the range infos the device reads, copied at the run's capture point (layer/capture).
  const uint32_t* captured = nullptr;
  if (data->capture_tracker) {
    if (const std::shared_ptr<CommandBufferState> recording = data->state.command_buffers.Find(commandBuffer)) {
      std::vector<uint32_t>& out = thread.data().captured_infos;
      if (CaptureIndirectRanges(MakeCaptureContext(*data), commandBuffer, *recording, infoCount, pInfos,
                                pIndirectDeviceAddresses, pIndirectStrides, ppMaxPrimitiveCounts, out)) {
        captured = out.data();
      }
      ReportCaptureBudget(MakeCheckContext(*data), data->instance->settings.capture_budget_mb,
                          "vkCmdBuildAccelerationStructuresIndirectKHR");
    }
  }
  data->dispatch.CmdBuildAccelerationStructuresIndirectKHR(commandBuffer, infoCount, pInfos, pIndirectDeviceAddresses,
                                                           pIndirectStrides, ppMaxPrimitiveCounts);
  // The ranges (and so the primitive counts) are on the device.
  RecordCmdBuild(data->state, commandBuffer, OpCommand::kCmdBuildIndirect, infoCount, pInfos, nullptr,
                 &thread.data().last_recorded, captured);
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
  // The inputs of updatable builds and updates, copied now (host memory): the activity rules judge them, and the
  // history keeps their activity. Only on a device with host commands enabled: otherwise the call is invalid
  // (features family) and its pointers, which may be device addresses, are never read.
  HostCapture capture;
  const LayerSettings& settings = data->instance->settings;
  if (settings.capture != kCaptureOff && data->state.history_tracked &&
      data->state.features.acceleration_structure_host_commands) {
    capture = CaptureHostBuildInputs(infoCount, pInfos, ppBuildRangeInfos, VkDeviceSize{settings.capture_budget_mb} << 20,
                                     data->state.capture_counters);
    cmd.host_capture = capture.log.get();
    cmd.host_captured = capture.captured_or_null();
  }
  // Skipped by the app's callback, or withheld by protect mode: the build did not happen.
  const ProtectScope protect(data->reporter->protects());
  if (ValidateBuildCommand(MakeCheckContext(*data), cmd)) {
    return WithholdHostCommand(*data, cmd.function, device, protect);
  }
  const VkResult result =
      data->dispatch.BuildAccelerationStructuresKHR(device, deferredOperation, infoCount, pInfos, ppBuildRangeInfos);
  // History: applied now on success, or when the deferred operation completes.
  FinishHostOps(data->state,
                HostBuildOps(infoCount, pInfos, ppBuildRangeInfos, capture.log.get(), capture.captured_or_null(),
                             data->state.properties.acceleration_structure.maxGeometryCount),
                deferredOperation, result, capture.log);
  return result;
}

}  // namespace asval::hooks
