#include "build_features.h"

#include "build_report.h"

namespace asval {

namespace {

// The feature the command needs, by command: the VUID suffix and the feature's name.
struct RequiredFeature {
  bool enabled;
  const char* vuid;
  const char* name;
};

RequiredFeature FeatureFor(const DeviceFeatures& f, BuildCommandKind kind) {
  switch (kind) {
    case BuildCommandKind::kCmdBuildIndirect:
      return {f.acceleration_structure_indirect_build, "accelerationStructureIndirectBuild-03650",
              "accelerationStructureIndirectBuild"};
    case BuildCommandKind::kHostBuild:
      return {f.acceleration_structure_host_commands, "accelerationStructureHostCommands-03581",
              "accelerationStructureHostCommands"};
    case BuildCommandKind::kCmdBuild:
      break;
  }
  return {f.acceleration_structure, "accelerationStructure-08923", "accelerationStructure"};
}

// The command buffer's record, looked up only when a protected pool exists (out of line: rare).
[[gnu::noinline]] bool ValidateProtectedByLookup(const CheckContext& ctx, const BuildCommand& cmd) {
  const std::shared_ptr<CommandBufferState> info = ctx.state.command_buffers.Find(cmd.command_buffer);
  if (!info) {
    CountUnknownState(ctx);
    return false;
  }
  if (!info->is_protected) return false;
  return ReportBuild(
      ctx, cmd, kNoInfo, "commandBuffer-09547", [&](std::string&) { return cmd.Root().Field("commandBuffer"); },
      "is a protected command buffer (allocated from VkCommandPool 0x{:x}, created with "
      "VK_COMMAND_POOL_CREATE_PROTECTED_BIT); acceleration structures cannot be built in protected command buffers.",
      reinterpret_cast<uint64_t>(info->pool));
}

bool ValidateProtectedCommandBuffer(const CheckContext& ctx, const BuildCommand& cmd) {
  // No protected pool was ever created on this device: no command buffer can be protected.
  if (!ctx.state.command_buffers.AnyProtectedPool()) return false;
  return ValidateProtectedByLookup(ctx, cmd);
}

// The reporting halves (cold, out of line, scalars only: the clean path keeps no message pieces in its frame).
[[gnu::cold, gnu::noinline]] bool ReportMissingFeature(const CheckContext& ctx, const BuildCommand& cmd,
                                                       const char* vuid, const char* name) {
  return ReportBuild(ctx, cmd, kNoInfo, vuid, [&](std::string&) { return cmd.Root(); },
                     "was called, but the VkPhysicalDeviceAccelerationStructureFeaturesKHR::{} feature was not "
                     "enabled when the device was created.",
                     name);
}

[[gnu::cold, gnu::noinline]] bool ReportUnknownMode(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  return ReportBuild(ctx, cmd, i, "mode-04628", [&](std::string&) { return InfoLocation(cmd, i).Field("mode"); },
                     "({}) is not a VkBuildAccelerationStructureModeKHR value (BUILD = 0, UPDATE = 1).",
                     static_cast<int32_t>(cmd.infos[i].mode));
}

[[gnu::cold, gnu::noinline]] bool ReportUpdateWithoutSource(const CheckContext& ctx, const BuildCommand& cmd,
                                                            uint32_t i) {
  return ReportBuild(ctx, cmd, i, "pInfos-04630",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("srcAccelerationStructure"); },
                     "is VK_NULL_HANDLE, but pInfos[{}].mode is VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR: "
                     "an update needs the structure it updates.",
                     i);
}

bool IsKnownMode(VkBuildAccelerationStructureModeKHR mode) {
  return mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR || mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
}

}  // namespace

bool ValidateBuildFeatures(const CheckContext& ctx, const BuildCommand& cmd) {
  bool skip = false;
  const RequiredFeature feature = FeatureFor(ctx.state.features, cmd.kind);
  if (!feature.enabled) skip |= ReportMissingFeature(ctx, cmd, feature.vuid, feature.name);
  if (!cmd.is_host()) skip |= ValidateProtectedCommandBuffer(ctx, cmd);
  if (!cmd.infos) return skip;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
    if (!IsKnownMode(info.mode)) {
      skip |= ReportUnknownMode(ctx, cmd, i);
    } else if (info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR &&
               info.srcAccelerationStructure == VK_NULL_HANDLE) {
      skip |= ReportUpdateWithoutSource(ctx, cmd, i);
    }
  }
  return skip;
}

}  // namespace asval
