#include "resolved_build.h"

#include <new>

#include "build_size_lookup.h"
#include "geometry_pass.h"

namespace asval {

// Per-thread storage of the per-info records, reused from call to call.
struct ResolvedWorkspace {
  bool in_use = false;
  std::vector<ResolvedInfo> infos;
};

namespace {

std::shared_ptr<const AccelerationStructureState> FindStructure(const DeviceState& state,
                                                                VkAccelerationStructureKHR handle) {
  if (handle == VK_NULL_HANDLE) return nullptr;
  std::optional<std::shared_ptr<const AccelerationStructureState>> record = state.acceleration_structures.find(handle);
  return record ? std::move(*record) : nullptr;
}

// This thread's workspace, or null while a resolution on this thread already holds it (an app callback that
// records a build from inside a report).
ResolvedWorkspace* TakeThreadWorkspace() {
  thread_local ResolvedWorkspace workspace;
  if (workspace.in_use) return nullptr;
  workspace.in_use = true;
  return &workspace;
}

// Out of line, so that the caller looks the thread-local address up once per call and keeps the reference
// (used in place, a thread_local in a shared library costs one __tls_get_addr call per use).
[[gnu::noinline]] BufferMemo& ThisThreadsMemo() {
  thread_local BufferMemo memo;
  return memo;
}

// Where pInfos[i]'s bytes are: the destination's buffer, the sizes and the scratch buffer. `previous`: the
// sizes of pInfos[i - 1] when known (a call that builds many structures of one shape often passes the same
// geometry and range arrays for each: their signature is then read once per call).
void Place(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, BufferMemo& memo,
           const std::optional<BuildSizes>& previous, ResolvedInfo& r) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  r.placed = true;
  if (r.dst) r.dst_buffer_known = memo.FindOfStructure(ctx.state, *r.dst, &r.dst_buffer);
  if (previous && SameSignatureArrays(cmd, i - 1, i)) {
    r.sizes = previous;
  } else {
    r.sizes = SizesOfInfo(ctx.state, cmd, i);
  }
  if (!r.sizes) return;
  r.scratch_bytes = info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ? r.sizes->update_scratch_size
                                                                                 : r.sizes->build_scratch_size;
  if (!cmd.is_host() && r.scratch_bytes != 0) {
    r.scratch_in_storage = memo.Holding(ctx.state, info.scratchData.deviceAddress, r.scratch_bytes,
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, &r.scratch_buffer);
  }
}

}  // namespace

ResolvedBuild::ResolvedBuild(const CheckContext& ctx, const BuildCommand& cmd) {
  const uint32_t count = cmd.infos ? cmd.info_count : 0;
  if (count <= kInlineInfos) {
    for (; inline_count_ < count; ++inline_count_) new (&inline_.infos[inline_count_]) ResolvedInfo();
    infos_ = inline_.infos;
  } else {
    w_ = TakeThreadWorkspace();
    if (!w_) {
      owned_ = std::make_unique<ResolvedWorkspace>();
      w_ = owned_.get();
    }
    w_->infos.clear();
    w_->infos.resize(count);
    infos_ = w_->infos.data();
  }
  if (!cmd.infos) return;
  const bool records = ctx.Enabled(static_cast<LayerSettingFlagBits>(kCheckHandles | kCheckAddresses | kCheckAliasing));
  const bool placement = ctx.Enabled(static_cast<LayerSettingFlagBits>(kCheckAddresses | kCheckAliasing));
  // The families with per-geometry rules; host builds are not screened (geometry_pass.h).
  const bool screening =
      !cmd.is_host() && ctx.Enabled(static_cast<LayerSettingFlagBits>(kCheckStructure | kCheckAlignment | kCheckAddresses));
  if (placement) {
    // Kept from call to call on this thread; Sync empties it when the buffers or their addresses changed.
    memo_ = &ThisThreadsMemo();
    memo_->Sync(ctx.state);
  }
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
    ResolvedInfo& r = infos_[i];
    if (records) {
      r.dst = FindStructure(ctx.state, info.dstAccelerationStructure);
      r.src = FindStructure(ctx.state, info.srcAccelerationStructure);
      if (placement) Place(ctx, cmd, i, *memo_, i > 0 ? infos_[i - 1].sizes : std::nullopt, r);
    }
    if (screening) ScreenGeometries(ctx, cmd, i, memo_, r);
  }
}

ResolvedBuild::~ResolvedBuild() {
  for (uint32_t k = 0; k < inline_count_; ++k) inline_.infos[k].~ResolvedInfo();
  if (w_ && !owned_) w_->in_use = false;
}

}  // namespace asval
