#include "build_aliasing.h"

#include <algorithm>
#include <vector>

#include "buffer_lookup.h"
#include "buffer_memo.h"
#include "check_thread_data.h"
#include "build_report.h"
#include "build_sizes.h"
#include "host_instances.h"

namespace asval {

namespace {

using Workspace = AliasingWorkspace;

constexpr int kMaxFindingsPerCall = 16;  // enough to show the pattern; a flood helps nobody

bool SameSpace(const AccessSpan& a, const AccessSpan& b) { return a.space == b.space; }

// The rule two overlapping spans break, or null when their overlap is allowed. `a` is the span of the lower
// kind (so pairs are named once).
const char* RuleFor(const AccessSpan& a, const AccessSpan& b) {
  const bool same_info = a.info == b.info;
  switch (a.kind) {
    case SpanKind::kDst:
      switch (b.kind) {
        case SpanKind::kDst:
          return same_info ? nullptr : "dstAccelerationStructure-03702";
        case SpanKind::kSrc:  // an info's own source: an in-place update (or pInfos-03668, checked apart)
          return same_info ? nullptr : "dstAccelerationStructure-03701";
        case SpanKind::kScratch:
          return "dstAccelerationStructure-03703";
        case SpanKind::kReferenced:
          return same_info ? nullptr : "dstAccelerationStructure-03706";
      }
      return nullptr;
    case SpanKind::kSrc:
      return b.kind == SpanKind::kScratch ? "scratchData-03705" : nullptr;  // sources may share bytes
    case SpanKind::kScratch:
      return b.kind == SpanKind::kScratch && !same_info ? "scratchData-03704" : nullptr;
    case SpanKind::kReferenced:
      return nullptr;
  }
  return nullptr;
}

const char* KindName(SpanKind kind) {
  switch (kind) {
    case SpanKind::kDst:
      return "dstAccelerationStructure";
    case SpanKind::kSrc:
      return "srcAccelerationStructure";
    case SpanKind::kScratch:
      return "scratchData";
    case SpanKind::kReferenced:
      return "a structure its instances reference";
  }
  return "";
}

std::string DescribeSpan(const AccessSpan& s) {
  if (s.space == kHostSpace) return fmt::format("host bytes [0x{:x}, 0x{:x})", s.begin, s.end);
  return fmt::format("bytes [0x{:x}, 0x{:x}) of VkDeviceMemory 0x{:x}", s.begin, s.end, s.space);
}

[[gnu::cold, gnu::noinline]] bool ReportOverlap(const CheckContext& ctx, const BuildCommand& cmd, const char* rule,
                                                const AccessSpan& a, const AccessSpan& b) {
  // The finding is about the span the rule is named after: a destination (0370x) or scratch (03704/05).
  const bool scratch_rule = rule[0] == 's';
  const AccessSpan& subject = scratch_rule && a.kind != SpanKind::kScratch ? b : a;
  const AccessSpan& other = &subject == &a ? b : a;
  const VkDeviceSize from = std::max(a.begin, b.begin);
  const VkDeviceSize to = std::min(a.end, b.end);
  std::string other_name = fmt::format("pInfos[{}].{}", other.info, KindName(other.kind));
  if (other.kind == SpanKind::kReferenced) {
    other_name = fmt::format("VkAccelerationStructureKHR 0x{:x}, which instances of pInfos[{}] reference",
                             reinterpret_cast<uint64_t>(other.structure), other.info);
  }
  return ReportBuild(ctx, cmd, subject.info, rule,
                     [&](std::string&) { return InfoLocation(cmd, subject.info).Field(KindName(subject.kind)); },
                     "({}, as this command accesses it) overlaps {} ({}) by {} bytes: [0x{:x}, 0x{:x}).",
                     DescribeSpan(subject), other_name, DescribeSpan(other), to - from, from, to);
}

// A structure's bytes this build accesses: `accessed` from its start, at most its size. False when the layer
// does not know where they are (unknown structure or buffer, not bound).
// Inlined into both callers (the sweep's collection and the one-build path), as it was with one caller.
[[gnu::always_inline]] inline bool StructureSpan(const AccelerationStructureState& structure, const KnownBuffer& buffer, VkDeviceSize accessed,
                   uint32_t info, SpanKind kind, AccessSpan* out) {
  if (!buffer.bound || buffer.memory == VK_NULL_HANDLE) return false;
  const VkDeviceSize begin = SaturatingAdd(buffer.memory_offset, structure.offset);
  *out = AccessSpan{reinterpret_cast<uint64_t>(buffer.memory), begin,
                    SaturatingAdd(begin, std::min(accessed, structure.size)), structure.handle, info, kind};
  return true;
}

// Same, for a structure whose buffer is not resolved yet (null: not a live structure).
bool StructureSpan(const DeviceState& state, BufferMemo& memo, const AccelerationStructureState* structure,
                   VkDeviceSize accessed, uint32_t info, SpanKind kind, AccessSpan* out) {
  KnownBuffer buffer;
  if (!structure || !memo.FindOfStructure(state, *structure, &buffer)) return false;
  return StructureSpan(*structure, buffer, accessed, info, kind, out);
}

// Same, for a structure known by handle only.
bool StructureSpan(const DeviceState& state, BufferMemo& memo, VkAccelerationStructureKHR handle, VkDeviceSize accessed,
                   uint32_t info, SpanKind kind, AccessSpan* out) {
  const std::optional<std::shared_ptr<const AccelerationStructureState>> structure =
      state.acceleration_structures.find(handle);
  return structure && StructureSpan(state, memo, structure->get(), accessed, info, kind, out);
}

[[gnu::always_inline]] inline bool ScratchSpan(const DeviceState& state, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
                 BufferMemo& memo, AccessSpan* out) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (cmd.is_host()) {
    const auto address = reinterpret_cast<uint64_t>(info.scratchData.hostAddress);
    if (address == 0) return false;
    *out = AccessSpan{kHostSpace, address, SaturatingAdd(address, r.scratch_bytes), VK_NULL_HANDLE, i,
                      SpanKind::kScratch};
    return true;
  }
  const VkDeviceAddress address = info.scratchData.deviceAddress;
  // The buffer the resolution found, else (a scratch outside STORAGE_BUFFER buffers) any holding it.
  const KnownBuffer* held = r.scratch_in_storage ? &r.scratch_buffer : nullptr;
  if (!held && !(held = memo.Held(state, address, r.scratch_bytes, 0))) {
    return false;  // not in one buffer: the addresses family reports it
  }
  const KnownBuffer& buffer = *held;
  if (!buffer.bound) return false;
  const VkDeviceSize begin = SaturatingAdd(buffer.memory_offset, address - buffer.base);
  *out = AccessSpan{reinterpret_cast<uint64_t>(buffer.memory), begin, SaturatingAdd(begin, r.scratch_bytes),
                    VK_NULL_HANDLE, i, SpanKind::kScratch};
  return true;
}

// The spans pInfos[i] accesses. Each one the layer cannot place is left out and counted.
void CollectSpans(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
                  BufferMemo& memo, Workspace& w) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (!r.sizes) return;  // counted by ValidateBuildMemory
  AccessSpan span;
  if (r.dst && r.dst_buffer_known &&
      StructureSpan(*r.dst, r.dst_buffer, r.sizes->acceleration_structure_size, i, SpanKind::kDst, &span)) {
    w.spans.push_back(span);
  } else {
    CountUnknownState(ctx);
  }
  if (info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR && info.srcAccelerationStructure != VK_NULL_HANDLE) {
    if (StructureSpan(ctx.state, memo, r.src, r.sizes->acceleration_structure_size, i, SpanKind::kSrc,
                      &span)) {
      w.spans.push_back(span);
    } else {
      CountUnknownState(ctx);
    }
  }
  if (r.scratch_bytes != 0) {
    if (ScratchSpan(ctx.state, cmd, i, r, memo, &span)) {
      w.spans.push_back(span);
    } else {
      CountUnknownState(ctx);
    }
  }
  if (!cmd.is_host()) return;
  // Host builds: the structures the instances reference are read by this command (dstAccelerationStructure-03706).
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    w.references.clear();
    if (!CollectInstanceReferences(ctx.state, cmd, i, j, w.references)) continue;
    for (uint64_t reference : w.references) {
      const auto handle = reinterpret_cast<VkAccelerationStructureKHR>(reference);
      // The whole structure: which of its bytes the build reads is the driver's business.
      if (StructureSpan(ctx.state, memo, handle, ~VkDeviceSize{0}, i, SpanKind::kReferenced, &span)) {
        w.spans.push_back(span);
      }
    }
  }
}

// Sort by (space, begin), then sweep keeping the spans that reach past the current one's start: each pair
// met is an overlap. With no overlaps the active list holds at most one span, so the sweep is linear.
bool SpanBefore(const AccessSpan& x, const AccessSpan& y) {
  if (x.space != y.space) return x.space < y.space;
  if (x.begin != y.begin) return x.begin < y.begin;
  return x.info < y.info;
}

// Up to this many spans (one info: a destination, a source, a scratch) an insertion sort in place, which is
// what std::sort does for so few elements (the same order, ties included), without its call and setup.
constexpr size_t kFewSpans = 16;

void SortSpans(std::vector<AccessSpan>& spans) {
  if (spans.size() > kFewSpans) {
    // Through a lambda, so that the comparison is inlined into the sort (a function pointer is called per comparison).
    std::sort(spans.begin(), spans.end(), [](const AccessSpan& x, const AccessSpan& y) { return SpanBefore(x, y); });
    return;
  }
  for (size_t k = 1; k < spans.size(); ++k) {
    const AccessSpan moving = spans[k];
    size_t to = k;
    for (; to > 0 && SpanBefore(moving, spans[to - 1]); --to) spans[to] = spans[to - 1];
    spans[to] = moving;
  }
}

// Whether the sweep certainly has nothing to report, found without sorting: up to kPairwiseSpans spans, no two
// overlap (every pair compared); up to kSpacesSpans spans, no two lie in the same memory (a small set of memory
// handles on the stack: apps that give each structure and each scratch its own allocation). Either way a
// possible overlap sends the command to the sort and sweep, which then report exactly what they always do.
constexpr size_t kPairwiseSpans = 4;
constexpr size_t kSpacesSpans = 64;

bool CertainlyDisjoint(const std::vector<AccessSpan>& spans) {
  if (spans.size() <= kPairwiseSpans) {
    for (size_t a = 0; a < spans.size(); ++a) {
      for (size_t b = a + 1; b < spans.size(); ++b) {
        const AccessSpan& x = spans[a];
        const AccessSpan& y = spans[b];
        if (SameSpace(x, y) && x.begin < y.end && y.begin < x.end) return false;
      }
    }
    return true;
  }
  if (spans.size() > kSpacesSpans) return false;
  constexpr uint32_t kSlots = 2 * kSpacesSpans;  // at most half full
  static_assert(kSlots == 128, "the slot is the top 7 bits of the hash");
  uint64_t spaces[kSlots] = {};  // 0 (kHostSpace) is an empty slot: host spans make this screen give up
  for (const AccessSpan& s : spans) {
    if (s.space == kHostSpace) return false;
    uint32_t k = static_cast<uint32_t>((s.space * 0x9e3779b97f4a7c15ull) >> 57);
    for (; spaces[k]; k = (k + 1) & (kSlots - 1)) {
      if (spaces[k] == s.space) return false;
    }
    spaces[k] = s.space;
  }
  return true;
}

bool SweepOverlaps(const CheckContext& ctx, const BuildCommand& cmd, Workspace& w) {
  if (CertainlyDisjoint(w.spans)) return false;
  SortSpans(w.spans);
  bool skip = false;
  int findings = 0;
  w.active.clear();
  for (uint32_t k = 0; k < w.spans.size(); ++k) {
    const AccessSpan& s = w.spans[k];
    if (s.begin >= s.end) continue;
    size_t kept = 0;
    for (uint32_t a : w.active) {
      const AccessSpan& t = w.spans[a];
      if (SameSpace(t, s) && t.end > s.begin) w.active[kept++] = a;
    }
    w.active.resize(kept);
    for (uint32_t a : w.active) {
      const AccessSpan& t = w.spans[a];
      const bool t_first = t.kind <= s.kind;
      const AccessSpan& lo = t_first ? t : s;
      const AccessSpan& hi = t_first ? s : t;
      if (const char* rule = RuleFor(lo, hi)) {
        skip |= ReportOverlap(ctx, cmd, rule, lo, hi);
        if (++findings >= kMaxFindingsPerCall) return skip;
      }
    }
    w.active.push_back(k);
  }
  return skip;
}

// pInfos-03668: an update whose source and destination differ must not alias them at all (whole structures).
[[gnu::cold, gnu::noinline]] bool ReportUpdateAliasing(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                       const AccessSpan& src, const AccessSpan& dst) {
  return ReportBuild(ctx, cmd, i, "pInfos-03668",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("srcAccelerationStructure"); },
                     "(VkAccelerationStructureKHR 0x{:x}, {}) and dstAccelerationStructure (VkAccelerationStructureKHR "
                     "0x{:x}, {}) of this update are different structures whose memory overlaps.",
                     reinterpret_cast<uint64_t>(src.structure), DescribeSpan(src),
                     reinterpret_cast<uint64_t>(dst.structure), DescribeSpan(dst));
}

bool ValidateUpdateAliasing(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
                            BufferMemo& memo) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (info.mode != VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR || info.srcAccelerationStructure == VK_NULL_HANDLE ||
      info.srcAccelerationStructure == info.dstAccelerationStructure) {
    return false;
  }
  AccessSpan src, dst;
  const VkDeviceSize whole = ~VkDeviceSize{0};
  if (!r.dst || !r.dst_buffer_known || !StructureSpan(*r.dst, r.dst_buffer, whole, i, SpanKind::kDst, &dst) ||
      !StructureSpan(ctx.state, memo, r.src, whole, i, SpanKind::kSrc, &src)) {
    CountUnknownState(ctx);
    return false;
  }
  if (!SameSpace(src, dst) || src.end <= dst.begin || dst.end <= src.begin) return false;
  return ReportUpdateAliasing(ctx, cmd, i, src, dst);
}

// None-03407 (host builds): no instance references another info's destination.
[[gnu::cold, gnu::noinline]] bool ReportReferencedDestination(const CheckContext& ctx, const BuildCommand& cmd,
                                                              uint32_t k, uint32_t j, uint32_t i, uint64_t reference) {
  const uint32_t instance = FirstInstanceReferencing(ctx.state, cmd, k, j, reference);
  return ReportBuild(ctx, cmd, k, "None-03407",
                     [&](std::string&) {
                       return GeometryLocation(cmd, k, j).Field("geometry").Field("instances").Field("data").Field(
                           "hostAddress");
                     },
                     "(instance {}) references VkAccelerationStructureKHR 0x{:x}, which is pInfos[{}]."
                     "dstAccelerationStructure of this same command.",
                     instance, reference, i);
}

bool ValidateReferencedDestinations(const CheckContext& ctx, const BuildCommand& cmd, Workspace& w) {
  w.destinations.clear();
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    w.destinations.emplace_back(reinterpret_cast<uint64_t>(cmd.infos[i].dstAccelerationStructure), i);
  }
  std::sort(w.destinations.begin(), w.destinations.end());
  bool skip = false;
  for (uint32_t k = 0; k < cmd.info_count; ++k) {
    if (cmd.infos[k].type != VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) continue;
    for (uint32_t j = 0; j < cmd.infos[k].geometryCount; ++j) {
      w.references.clear();
      if (!CollectInstanceReferences(ctx.state, cmd, k, j, w.references)) continue;
      for (uint64_t reference : w.references) {
        auto it = std::lower_bound(w.destinations.begin(), w.destinations.end(), std::make_pair(reference, 0u));
        for (; it != w.destinations.end() && it->first == reference; ++it) {
          if (it->second != k) {
            skip |= ReportReferencedDestination(ctx, cmd, k, j, it->second, reference);
            break;
          }
        }
      }
    }
  }
  return skip;
}

Workspace& ClearedWorkspace(CheckThreadData& thread) {
  if (!thread.aliasing) thread.aliasing = std::make_unique<AliasingWorkspace>();
  thread.aliasing->spans.clear();
  return *thread.aliasing;
}

}  // namespace

// CollectSpans for pInfos[0] without a source span (pInfos-03668 needs one too: nothing to check), then the
// sweep only when the two spans may overlap: CertainlyDisjoint's pairwise test on two spans, the same one.
namespace {

[[gnu::noinline]] bool ValidateOneBuildAliasingFully(const CheckContext& ctx, const BuildCommand& cmd,
                                                     const ResolvedInfo& r, BufferMemo& memo, CheckThreadData& thread) {
  if (!r.sizes) return false;  // counted by ValidateBuildMemory
  AccessSpan dst, scratch;
  const bool has_dst =
      r.dst && r.dst_buffer_known &&
      StructureSpan(*r.dst, r.dst_buffer, r.sizes->acceleration_structure_size, 0, SpanKind::kDst, &dst);
  if (!has_dst) CountUnknownState(ctx);
  bool has_scratch = false;
  if (r.scratch_bytes != 0) {
    has_scratch = ScratchSpan(ctx.state, cmd, 0, r, memo, &scratch);
    if (!has_scratch) CountUnknownState(ctx);
  }
  if (!has_dst || !has_scratch || !SameSpace(dst, scratch) || !(dst.begin < scratch.end && scratch.begin < dst.end)) {
    return false;
  }
  Workspace& w = ClearedWorkspace(thread);
  w.spans.push_back(dst);
  w.spans.push_back(scratch);
  return SweepOverlaps(ctx, cmd, w);
}

}  // namespace

bool ValidateOneBuildAliasing(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedInfo& r, BufferMemo& memo,
                              CheckThreadData& thread) {
  if (OneBuildAliasingClean(cmd, r)) return false;  // before any call: no stack frame
  return ValidateOneBuildAliasingFully(ctx, cmd, r, memo, thread);
}

AliasingSweep::AliasingSweep(CheckThreadData& thread) : w_(&ClearedWorkspace(thread)) {}

bool AliasingSweep::AddInfo(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r,
                            BufferMemo& memo) {
  CollectSpans(ctx, cmd, i, r, memo, *w_);
  return ValidateUpdateAliasing(ctx, cmd, i, r, memo);
}

bool AliasingSweep::Finish(const CheckContext& ctx, const BuildCommand& cmd) {
  bool skip = SweepOverlaps(ctx, cmd, *w_);
  if (cmd.is_host()) skip |= ValidateReferencedDestinations(ctx, cmd, *w_);
  return skip;
}

}  // namespace asval
