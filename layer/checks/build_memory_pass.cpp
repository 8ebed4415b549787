#include "build_memory_pass.h"

#include <optional>

#include "build_addresses.h"
#include "build_aliasing.h"
#include "build_report.h"

namespace asval {

bool ValidateBuildMemory(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  if (!cmd.infos) return false;
  const bool addresses = ctx.Enabled(kCheckAddresses);
  const bool aliasing = ctx.Enabled(kCheckAliasing);
  bool skip = false;
  if (aliasing && IsOneBuildAliasing(cmd)) {  // the common single build: no sweep to set up
    const ResolvedInfo& r = resolved.info(0);
    // The clean single build (nothing either family reports or counts) before any call: no stack frame.
    if ((!addresses || InfoAddressesClean(cmd, r)) && OneBuildAliasingClean(cmd, r)) return false;
    if (!r.sizes) CountUnknownState(ctx);  // the sizes of this build cannot be known
    if (addresses) skip |= ValidateInfoAddresses(ctx, cmd, 0, r, resolved.memo());
    return skip | ValidateOneBuildAliasing(ctx, cmd, r, resolved.memo(), resolved.thread());
  }
  std::optional<AliasingSweep> sweep;
  if (aliasing) sweep.emplace(resolved.thread());
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const ResolvedInfo& r = resolved.info(i);
    if (!r.sizes) CountUnknownState(ctx);  // the sizes of this build cannot be known
    if (addresses) skip |= ValidateInfoAddresses(ctx, cmd, i, r, resolved.memo());
    if (aliasing) skip |= sweep->AddInfo(ctx, cmd, i, r, resolved.memo());
  }
  if (aliasing) skip |= sweep->Finish(ctx, cmd);
  return skip;
}

}  // namespace asval
