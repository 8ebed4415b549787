#include "build_report.h"

namespace asval {

bool ReportBuildFinding(const CheckContext& ctx, const BuildCommand& cmd, uint32_t info_index, std::string_view vuid,
                        const Location& loc, std::string_view message) {
  std::string full;
  if (vuid.rfind("VUID-", 0) == 0) {
    full = vuid;
  } else {
    full.append("VUID-").append(cmd.function).append("-").append(vuid);
  }
  const ReportObject where = cmd.is_host() ? Obj(VK_OBJECT_TYPE_DEVICE, cmd.device)
                                           : Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, cmd.command_buffer);
  const VkAccelerationStructureKHR dst =
      info_index < cmd.info_count ? cmd.infos[info_index].dstAccelerationStructure : VK_NULL_HANDLE;
  return ctx.reporter.Report(Severity::kError, full, loc, {where, Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, dst)},
                             message);
}

}  // namespace asval
