#pragma once
// One build command as every rule family sees it, resolved once per call: for each info, the records of its
// destination and source structures, the buffer under the destination, the driver's sizes for this build and
// the buffer that holds its scratch. Before this view each family looked these up on its own (the destination
// twice per info, the sizes and scratch once per family). Computed by ResolveBuild (checks code, const over the
// shadow state); a family reads it and never changes it.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "buffer_memo.h"
#include "build_command.h"
#include "build_size_cache.h"
#include "check_context.h"
#include "objects.h"

namespace asval {

// The per-geometry walks of the families (ResolvedInfo::walks): the structure family's geometry rules
// (build_structure.h), its range rules (build_ranges.h), the alignment family's input rules
// (build_input_alignment.h), the addresses family's input reads (build_input_reads.h) and instance counts
// (build_sizes.h).
enum GeometryWalk : uint8_t {
  kWalkStructure = 1u << 0,
  kWalkRanges = 1u << 1,
  kWalkInputAlignment = 1u << 2,
  kWalkInputReads = 1u << 3,
  kWalkInstanceCounts = 1u << 4,
  kWalkAll = (1u << 5) - 1,
};

struct ResolvedInfo {
  // User-provided, so that value-initialization (ResolvedInfo(), vector::resize) runs the member initializers
  // only, without zeroing the whole record first.
  ResolvedInfo() {}

  // The families that must walk this info's geometries themselves: the geometry pass (geometry_pass.h) found
  // something to report or count for them, or did not screen this info. The others' rules found nothing.
  uint8_t walks = kWalkAll;
  // dstAccelerationStructure's record; null when the handle is not a live structure of this device.
  const AccelerationStructureState* dst = nullptr;
  // srcAccelerationStructure's record; null when the handle is VK_NULL_HANDLE or not a live structure.
  const AccelerationStructureState* src = nullptr;
  // Both stay valid for the call: the thread's structure memo holds them, or, when it could not, these do.
  std::shared_ptr<const AccelerationStructureState> dst_held;
  std::shared_ptr<const AccelerationStructureState> src_held;
  // The rest is resolved only when the addresses or aliasing family is on (placed = true).
  bool placed = false;
  // The destination's buffer (dst_buffer_known: the layer knows it).
  KnownBuffer dst_buffer;
  bool dst_buffer_known = false;
  std::optional<BuildSizes> sizes;  // nullopt: unknown (the family that needs them counts it)
  // Bytes of scratch this build needs (build or update size), and, for device builds, the buffer holding
  // them all with STORAGE_BUFFER usage when there is one.
  VkDeviceSize scratch_bytes = 0;
  bool scratch_in_storage = false;
  KnownBuffer scratch_buffer;
};

struct CheckThreadData;

// The view of one call. Lives on the hook's stack for the duration of the validation; its per-info records
// live there too for small calls, else in the thread's data (check_thread_data.h), which keeps its capacity,
// so a steady stream of calls allocates nothing.
class ResolvedBuild {
 public:
  // thread: this call's lease of the thread's data (memos, buffers), held for the whole validation.
  ResolvedBuild(const CheckContext& ctx, const BuildCommand& cmd, CheckThreadData& thread);
  ~ResolvedBuild() {
    for (uint32_t k = 0; k < inline_count_; ++k) inline_.infos[k].~ResolvedInfo();
  }
  ResolvedBuild(const ResolvedBuild&) = delete;
  ResolvedBuild& operator=(const ResolvedBuild&) = delete;

  // pInfos[i] resolved (i < cmd.info_count; empty records when cmd.infos is null).
  const ResolvedInfo& info(uint32_t i) const { return infos_[i]; }
  // The union of the infos' walks: a family whose bit is clear walks no info's geometries at all.
  uint8_t walks() const { return walks_; }
  // This thread's buffer memo, synced for this call: the families' further lookups (geometry inputs, the
  // source's buffer) go through it. Only when placement was resolved (addresses or aliasing on).
  BufferMemo& memo() const { return *memo_; }
  // This call's lease of the thread's data (the aliasing sweep's buffers).
  CheckThreadData& thread() const { return thread_; }

 private:
  // Calls of up to this many infos keep their records on the stack (no per-thread lookup, no vector).
  static constexpr uint32_t kInlineInfos = 2;
  union Inline {
    Inline() {}
    ~Inline() {}
    ResolvedInfo infos[kInlineInfos];
  } inline_;
  uint32_t inline_count_ = 0;  // records constructed in inline_
  uint8_t walks_ = kWalkAll;
  CheckThreadData& thread_;
  ResolvedInfo* infos_ = nullptr;
  BufferMemo* memo_ = nullptr;
};

}  // namespace asval
