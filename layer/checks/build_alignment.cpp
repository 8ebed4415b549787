#include "build_alignment.h"

#include <fmt/format.h>

#include "build_input_alignment.h"

namespace asval {

namespace {

// The reporting half lives out of line: the clean path of a check is then a few loads, a compare and a
// return, without the stack frame that building a message needs.
[[gnu::cold, gnu::noinline]] bool ReportMisalignedScratch(const CheckContext& ctx, const BuildCommand& cmd,
                                                          uint32_t index, uint32_t alignment) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[index];
  const VkDeviceAddress address = info.scratchData.deviceAddress;
  return ctx.reporter.Report(
      Severity::kError, cmd.Vuid("pInfos-03710"),
      cmd.Root().Field("pInfos", index).Field("scratchData").Field("deviceAddress"),
      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, cmd.command_buffer),
       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, info.dstAccelerationStructure)},
      fmt::format("(0x{:x}) is not a multiple of VkPhysicalDeviceAccelerationStructurePropertiesKHR::"
                  "minAccelerationStructureScratchOffsetAlignment ({}); it is {} bytes past the previous multiple.",
                  address, alignment, address % alignment));
}

bool ValidateScratchAlignment(const CheckContext& ctx, const BuildCommand& cmd) {
  const uint32_t alignment = ctx.state.properties.acceleration_structure.minAccelerationStructureScratchOffsetAlignment;
  if (alignment == 0) {
    // The driver's limit is unknown (no properties2 on this instance): nothing to compare with.
    ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    if (cmd.infos[i].scratchData.deviceAddress % alignment != 0) skip |= ReportMisalignedScratch(ctx, cmd, i, alignment);
  }
  return skip;
}

}  // namespace

bool ValidateBuildAlignment(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  if (!cmd.infos) return false;
  // The clean path of a direct device build, before any call (no stack frame): the limit known, every scratch
  // aligned, no input rule to walk.
  const uint32_t alignment = ctx.state.properties.acceleration_structure.minAccelerationStructureScratchOffsetAlignment;
  if (cmd.kind == BuildCommandKind::kCmdBuild && alignment != 0 && !(resolved.walks() & kWalkInputAlignment)) {
    uint32_t i = 0;
    while (i < cmd.info_count && cmd.infos[i].scratchData.deviceAddress % alignment == 0) ++i;
    if (i == cmd.info_count) return false;
  }
  bool skip = false;
  if (cmd.is_host()) return skip;  // host builds read host addresses: no alignment rule (ValidateInputAlignment agrees)
  skip |= ValidateScratchAlignment(ctx, cmd);
  // The input rules have nothing to walk unless the geometry pass flagged an info, or the indirect arrays.
  if ((resolved.walks() & kWalkInputAlignment) || cmd.is_indirect()) skip |= ValidateInputAlignment(ctx, cmd, resolved);
  return skip;
}

}  // namespace asval
