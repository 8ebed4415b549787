#include "build_memory_pass.h"

#include "build_addresses.h"
#include "build_aliasing.h"
#include "build_sizes.h"

namespace asval {

namespace {

InfoResolution Resolve(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo& memo) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  InfoResolution r;
  r.sizes = SizesOfInfo(ctx, cmd, i);
  if (std::optional<std::shared_ptr<const AccelerationStructureState>> dst =
          ctx.state.acceleration_structures.find(info.dstAccelerationStructure)) {
    r.dst = std::move(*dst);
  }
  if (r.dst) r.dst_buffer_known = memo.Find(ctx.state, r.dst->buffer, &r.dst_buffer);
  if (!r.sizes) return r;
  r.scratch_bytes = info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? r.sizes->update_scratch_size
                                                                                 : r.sizes->build_scratch_size;
  if (!cmd.is_host() && r.scratch_bytes != 0) {
    r.scratch_in_storage = memo.Holding(ctx.state, info.scratchData.deviceAddress, r.scratch_bytes,
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, &r.scratch_buffer);
  }
  return r;
}

}  // namespace

bool ValidateBuildMemory(const CheckContext& ctx, const BuildCommand& cmd) {
  if (!cmd.infos) return false;
  const bool addresses = ctx.Enabled(kCheckAddresses);
  const bool aliasing = ctx.Enabled(kCheckAliasing);
  BufferMemo memo;
  std::optional<AliasingSweep> sweep;
  if (aliasing) sweep.emplace();
  bool skip = false;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const InfoResolution r = Resolve(ctx, cmd, i, memo);
    if (addresses) skip |= ValidateInfoAddresses(ctx, cmd, i, r, memo);
    if (aliasing) skip |= sweep->AddInfo(ctx, cmd, i, r, memo);
  }
  if (aliasing) skip |= sweep->Finish(ctx, cmd);
  return skip;
}

}  // namespace asval
