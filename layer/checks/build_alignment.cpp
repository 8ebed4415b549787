#include "build_alignment.h"

#include <fmt/format.h>

namespace asval {

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
    const VkDeviceAddress address = infos[i].scratchData.deviceAddress;
    if (address % alignment == 0) continue;
    const Location field = loc.Field("pInfos", i).Field("scratchData").Field("deviceAddress");
    skip |= ctx.reporter.Report(
        Severity::kError, vuid, field,
        {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, command_buffer),
         Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, infos[i].dstAccelerationStructure)},
        fmt::format("(0x{:x}) is not a multiple of VkPhysicalDeviceAccelerationStructurePropertiesKHR::"
                    "minAccelerationStructureScratchOffsetAlignment ({}); it is {} bytes past the previous multiple.",
                    address, alignment, address % alignment));
  }
  return skip;
}

}  // namespace asval
