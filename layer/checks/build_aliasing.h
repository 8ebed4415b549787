#pragma once
// Memory aliasing inside one build command (family "aliasing"), for all three commands:
//   dstAccelerationStructure-03701   a destination overlaps the source of another info's update
//   dstAccelerationStructure-03702   two infos' destinations overlap
//   dstAccelerationStructure-03703   a destination overlaps any info's scratch (its own included)
//   scratchData-03704                two infos' scratch overlap
//   scratchData-03705                scratch overlaps any update's source (its own included)
//   pInfos-03668                     an update's source and destination are one structure or do not alias
//   host builds, whose instances are readable when called:
//   None-03407                       an instance references another info's destination
//   dstAccelerationStructure-03706   a destination overlaps a structure another info's instances reference
// "The memory accessed by this command" is the bytes the build really touches: accelerationStructureSize of
// a destination or source (at most the structure's size), buildScratchSize or updateScratchSize of scratch,
// all as the driver reports them for this build. They are compared as VkDeviceMemory offsets, so two buffers
// over one allocation alias. The spans are sorted and swept once: O(n log n) for n infos, no all-pairs loop.
// In-place updates (src == dst) are valid: an info's destination and its own source may be the same bytes.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "buffer_lookup.h"
#include "buffer_memo.h"
#include "build_command.h"
#include "resolved_build.h"
#include "check_context.h"

namespace asval {

struct CheckThreadData;

// What a span of memory is to its info. The order matters only for naming pairs (lower kind first).
enum class SpanKind : uint8_t { kDst, kSrc, kScratch, kReferenced };

// Bytes one info accesses: [begin, end) of a VkDeviceMemory (space = its handle), or of the host's address
// space (host builds' scratch; space = kHostSpace: no VkDeviceMemory handle is 0).
inline constexpr uint64_t kHostSpace = 0;
struct AccessSpan {
  uint64_t space;
  VkDeviceSize begin;
  VkDeviceSize end;
  VkAccelerationStructureKHR structure;  // kDst / kSrc / kReferenced
  uint32_t info;
  SpanKind kind;
};

// The sweep's buffers, kept in the thread's data (check_thread_data.h) from call to call, so that a steady
// stream of builds allocates nothing.
struct AliasingWorkspace {
  std::vector<AccessSpan> spans;
  std::vector<uint32_t> active;
  std::vector<uint64_t> references;
  std::vector<std::pair<uint64_t, uint32_t>> destinations;  // (handle, info), sorted
};

// One command's sweep (called by ValidateBuildMemory): AddInfo for each info, then Finish.
class AliasingSweep {
 public:
  explicit AliasingSweep(CheckThreadData& thread);
  AliasingSweep(const AliasingSweep&) = delete;
  AliasingSweep& operator=(const AliasingSweep&) = delete;
  // Collects the spans pInfos[i] accesses (each one the layer cannot place is left out and counted) and
  // checks pInfos-03668 for it.
  bool AddInfo(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
               BufferMemo& memo);
  // The overlaps among all the spans; for host builds, None-03407.
  bool Finish(const CheckContext& ctx, const BuildCommand& cmd);

 private:
  AliasingWorkspace* w_;
};

// Whether the command is one device build whose info is no update from another source: only its destination and
// its scratch can overlap then (dstAccelerationStructure-03703), and ValidateOneBuildAliasing judges it.
inline bool IsOneBuildAliasing(const BuildCommand& cmd) {
  if (cmd.info_count != 1 || cmd.is_host()) return false;
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[0];
  return info.mode != VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR || info.srcAccelerationStructure == VK_NULL_HANDLE;
}
// Whether ValidateOneBuildAliasing certainly has nothing to report or count: the destination's span is known, and
// the scratch is empty or lies in the bound buffer the resolution found, in other memory or other bytes (the same
// spans and overlap test as the rule's). Compares only: tested before any call.
inline bool OneBuildAliasingClean(const BuildCommand& cmd, const ResolvedInfo& r) {
  if (!r.sizes || !r.dst || !r.dst_buffer_known || !r.dst_buffer.bound || r.dst_buffer.memory == VK_NULL_HANDLE) {
    return false;
  }
  if (r.scratch_bytes == 0) return true;  // no scratch span
  if (!r.scratch_in_storage || !r.scratch_buffer.bound) return false;
  const KnownBuffer& b = r.dst_buffer;
  const VkDeviceSize dst_begin = SaturatingAdd(b.memory_offset, r.dst->offset);
  const VkDeviceSize dst_end = SaturatingAdd(dst_begin, std::min(r.sizes->acceleration_structure_size, r.dst->size));
  const KnownBuffer& s = r.scratch_buffer;
  const VkDeviceSize scratch_begin = SaturatingAdd(s.memory_offset, cmd.infos[0].scratchData.deviceAddress - s.base);
  const VkDeviceSize scratch_end = SaturatingAdd(scratch_begin, r.scratch_bytes);
  return s.memory != b.memory || !(dst_begin < scratch_end && scratch_begin < dst_end);
}

// The aliasing rules for such a command, instead of an AliasingSweep: the same findings and unknown-state counts,
// without collecting the spans unless the two may overlap (then the sweep judges them, as it always did).
bool ValidateOneBuildAliasing(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedInfo& r, BufferMemo& memo,
                              CheckThreadData& thread);

}  // namespace asval
