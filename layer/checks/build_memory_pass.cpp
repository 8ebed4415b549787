#include "build_memory_pass.h"

#include "build_addresses.h"
#include "build_aliasing.h"
#include "build_sizes.h"

namespace asval {

namespace {

// `previous`: the sizes of pInfos[i - 1] when known (a call that builds many structures of one shape often
// passes the same geometry and range arrays for each: their signature is then read once per call).
InfoResolution Resolve(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo& memo,
                       const std::optional<BuildSizes>& previous) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  InfoResolution r;
  if (previous && SameSignatureArrays(cmd, i - 1, i)) {
    r.sizes = previous;
  } else {
    r.sizes = SizesOfInfo(ctx, cmd, i);
  }
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

// Out of line, so that the caller looks the thread-local address up once per call and keeps the reference
// (used in place, a thread_local in a shared library costs one __tls_get_addr call per use).
[[gnu::noinline]] BufferMemo& ThisThreadsMemo() {
  thread_local BufferMemo memo;
  return memo;
}

}  // namespace

bool ValidateBuildMemory(const CheckContext& ctx, const BuildCommand& cmd) {
  if (!cmd.infos) return false;
  const bool addresses = ctx.Enabled(kCheckAddresses);
  const bool aliasing = ctx.Enabled(kCheckAliasing);
  // Kept from call to call on this thread; Sync empties it when the buffers or their addresses changed.
  BufferMemo& memo = ThisThreadsMemo();
  memo.Sync(ctx.state);
  std::optional<AliasingSweep> sweep;
  if (aliasing) sweep.emplace();
  bool skip = false;
  std::optional<BuildSizes> previous_sizes;
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const InfoResolution r = Resolve(ctx, cmd, i, memo, previous_sizes);
    previous_sizes = r.sizes;
    if (addresses) skip |= ValidateInfoAddresses(ctx, cmd, i, r, memo);
    if (aliasing) skip |= sweep->AddInfo(ctx, cmd, i, r, memo);
  }
  if (aliasing) skip |= sweep->Finish(ctx, cmd);
  return skip;
}

}  // namespace asval
