#include "build_alignment.h"

#include <fmt/format.h>

namespace asval {

namespace {

// The reporting half lives out of line: the clean path of a check is then a few loads, a compare and a
// return, without the stack frame that building a message needs.
[[gnu::cold, gnu::noinline]] bool ReportMisalignedScratch(const CheckContext& ctx, const Location& loc,
                                                          VkCommandBuffer command_buffer, uint32_t index,
                                                          const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                                          uint32_t alignment, const char* vuid) {
  const VkDeviceAddress address = info.scratchData.deviceAddress;
  return ctx.reporter.Report(
      Severity::kError, vuid, loc.Field("pInfos", index).Field("scratchData").Field("deviceAddress"),
      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, command_buffer),
       Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, info.dstAccelerationStructure)},
      fmt::format("(0x{:x}) is not a multiple of VkPhysicalDeviceAccelerationStructurePropertiesKHR::"
                  "minAccelerationStructureScratchOffsetAlignment ({}); it is {} bytes past the previous multiple.",
                  address, alignment, address % alignment));
}

}  // namespace

bool ValidateScratchAlignment(const CheckContext& ctx, const Location& loc, VkCommandBuffer command_buffer,
                              uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                              const char* vuid) {
  const uint32_t alignment = ctx.state.properties.acceleration_structure.minAccelerationStructureScratchOffsetAlignment;
  if (alignment == 0 || !infos) {
    // The driver's limit is unknown (no properties2 on this instance): nothing to compare with.
    ctx.state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  bool skip = false;
  for (uint32_t i = 0; i < info_count; ++i) {
    if (infos[i].scratchData.deviceAddress % alignment != 0) {
      skip |= ReportMisalignedScratch(ctx, loc, command_buffer, i, infos[i], alignment, vuid);
    }
  }
  return skip;
}

}  // namespace asval
