#include "resolved_build.h"

#include <new>

#include "build_size_lookup.h"
#include "check_thread_data.h"
#include "geometry_pass.h"

namespace asval {

namespace {

// Where pInfos[i]'s bytes are: the destination's buffer, the sizes and the scratch buffer. `previous`: the
// sizes of pInfos[i - 1] when pInfos[i] passes the very same arrays (null otherwise; a call that builds many
// structures of one shape often passes the same geometry and range arrays for each: their signature is then
// read once per call).
void Place(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, CheckThreadData& thread,
           const std::optional<BuildSizes>* previous, ResolvedInfo& r) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  BufferMemo& memo = thread.buffers;
  const bool hinted = i < CheckThreadData::kHintedInfos;
  r.placed = true;
  if (r.dst) {
    r.dst_buffer_known = memo.FindOfStructureHinted(
        ctx.state, *r.dst, hinted ? thread.dst_buffer_hints[i] : thread.spare_hint, &r.dst_buffer);
  }
  if (previous && *previous) {
    r.sizes = *previous;
  } else {
    r.sizes = SizesOfInfo(ctx.state, cmd, i, &thread.sizes);
  }
  if (!r.sizes) return;
  r.scratch_bytes = info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? r.sizes->update_scratch_size
                                                                                 : r.sizes->build_scratch_size;
  if (!cmd.is_host() && r.scratch_bytes != 0) {
    r.scratch_in_storage =
        memo.HoldingHinted(ctx.state, info.scratchData.deviceAddress, r.scratch_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                           hinted ? thread.scratch_hints[i] : thread.spare_hint, &r.scratch_buffer);
  }
}

}  // namespace

ResolvedBuild::ResolvedBuild(const CheckContext& ctx, const BuildCommand& cmd, CheckThreadData& thread)
    : thread_(thread) {
  const uint32_t count = cmd.infos ? cmd.info_count : 0;
  if (count <= kInlineInfos) {
    for (; inline_count_ < count; ++inline_count_) new (&inline_.infos[inline_count_]) ResolvedInfo();
    infos_ = inline_.infos;
  } else {
    thread.infos.clear();
    thread.infos.resize(count);
    infos_ = thread.infos.data();
  }
  if (!cmd.infos) return;
  walks_ = 0;
  const bool records = ctx.Enabled(static_cast<LayerSettingFlagBits>(kCheckHandles | kCheckAddresses | kCheckAliasing));
  const bool placement = ctx.Enabled(static_cast<LayerSettingFlagBits>(kCheckAddresses | kCheckAliasing));
  // The families with per-geometry rules; host builds are not screened (geometry_pass.h).
  const bool screening =
      !cmd.is_host() && ctx.Enabled(static_cast<LayerSettingFlagBits>(kCheckStructure | kCheckAlignment | kCheckAddresses));
  // Both memos are kept from call to call on this thread; Sync empties them when their maps changed.
  if (records) thread.structures.Sync(ctx.state);
  if (placement) {
    memo_ = &thread.buffers;
    memo_->Sync(ctx.state);
  }
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
    ResolvedInfo& r = infos_[i];
    // pInfos[i] passes the very same geometry and count arrays as pInfos[i - 1] (SameSignatureArrays): it has
    // the same sizes and the same answers from every per-geometry rule.
    const bool same_arrays = i > 0 && SameSignatureArrays(cmd, i - 1, i);
    if (records) {
      r.dst = thread.structures.Find(ctx.state, info.dstAccelerationStructure, r.dst_held);
      r.src = thread.structures.Find(ctx.state, info.srcAccelerationStructure, r.src_held);
      if (placement) Place(ctx, cmd, i, thread, same_arrays ? &infos_[i - 1].sizes : nullptr, r);
    }
    if (screening) {
      // An info that passes the very same geometry and count arrays as the one before, with the same type
      // (SameSignatureArrays), gets the same answer from every per-geometry rule: only the indices in a message
      // would differ, and the families walk the info themselves when there is a message.
      if (same_arrays) {
        r.walks = infos_[i - 1].walks;
      } else {
        ScreenGeometries(ctx, cmd, i, memo_, r);
      }
    }
    walks_ |= r.walks;
  }
}

}  // namespace asval
