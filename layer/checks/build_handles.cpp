#include "build_handles.h"

#include "structure_memory.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "build_report.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

// Up to this many infos the duplicate rules compare all pairs (n^2 / 2 compares, no buffer); beyond, they sort.
constexpr uint32_t kFewInfos = 16;

// The reporting halves of the per-info rules below (cold, out of line, scalars only: the clean path keeps no
// message pieces in its frame).
[[gnu::cold, gnu::noinline]] bool ReportDestinationType(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                        const AccelerationStructureState& dst, const char* vuid) {
  const VkAccelerationStructureTypeKHR type = cmd.infos[i].type;
  return ReportBuild(ctx, cmd, i, vuid,
                     [&](std::string&) { return InfoLocation(cmd, i).Field("dstAccelerationStructure"); },
                     "(0x{:x}) was created with VkAccelerationStructureCreateInfoKHR::type {}, but pInfos[{}].type is "
                     "{}: it must have been created with that type or VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR.",
                     reinterpret_cast<uint64_t>(dst.handle), string_VkAccelerationStructureTypeKHR(dst.type), i,
                     string_VkAccelerationStructureTypeKHR(type));
}

[[gnu::cold, gnu::noinline]] bool ReportInvalidDestination(const CheckContext& ctx, const BuildCommand& cmd,
                                                           uint32_t i) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  return ReportBuild(ctx, cmd, i, "dstAccelerationStructure-03800",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("dstAccelerationStructure"); },
                     "(0x{:x}) is not a valid VkAccelerationStructureKHR: {}.",
                     reinterpret_cast<uint64_t>(info.dstAccelerationStructure),
                     info.dstAccelerationStructure ? "no live acceleration structure of this device has this handle"
                                                   : "it is VK_NULL_HANDLE");
}

[[gnu::cold, gnu::noinline]] bool ReportInvalidSource(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  return ReportBuild(ctx, cmd, i, "srcAccelerationStructure-04629",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("srcAccelerationStructure"); },
                     "(0x{:x}) is not VK_NULL_HANDLE and not a valid VkAccelerationStructureKHR: no live "
                     "acceleration structure of this device has this handle.",
                     reinterpret_cast<uint64_t>(cmd.infos[i].srcAccelerationStructure));
}

// pInfos-03699 / 03700: the build's type against the type the destination was created with.
bool ValidateDestinationType(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                             const AccelerationStructureState& dst) {
  const VkAccelerationStructureTypeKHR type = cmd.infos[i].type;
  const char* vuid = nullptr;
  if (type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
    vuid = "pInfos-03699";
  } else if (type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) {
    vuid = "pInfos-03700";
  } else {
    return false;  // GENERIC is a structure rule of its own (type-03654)
  }
  if (dst.type == type || dst.type == VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR) return false;
  return ReportDestinationType(ctx, cmd, i, dst, vuid);
}

[[gnu::cold, gnu::noinline]] bool ReportMotionMismatch(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                      bool created_with_motion) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (created_with_motion) {
    return ReportBuild(ctx, cmd, i, "VUID-VkAccelerationStructureBuildGeometryInfoKHR-dstAccelerationStructure-04927",
                       [&](std::string&) { return InfoLocation(cmd, i).Field("flags"); },
                       "(0x{:x}) lacks VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV, but dstAccelerationStructure "
                       "(0x{:x}) was created with VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV.",
                       info.flags, reinterpret_cast<uint64_t>(info.dstAccelerationStructure));
  }
  return ReportBuild(
      ctx, cmd, i, "VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-04928",
      [&](std::string&) { return InfoLocation(cmd, i).Field("flags"); },
      "(0x{:x}) has VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV, but dstAccelerationStructure (0x{:x}) "
      "was created without VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV.",
      info.flags, reinterpret_cast<uint64_t>(info.dstAccelerationStructure));
}

// dstAccelerationStructure-04927 / flags-04928: a motion build into a structure created for motion, and only there.
bool ValidateMotion(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                    const AccelerationStructureState& dst) {
  const bool created_with_motion = (dst.create_flags & VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV) != 0;
  const bool built_with_motion = (cmd.infos[i].flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0;
  if (created_with_motion == built_with_motion) return false;
  return ReportMotionMismatch(ctx, cmd, i, created_with_motion);
}

// pInfos-03707 / 03708: the structure's buffer is bound. Unknown buffers and sparse buffers (bound through
// vkQueueBindSparse, which the layer does not follow) are skipped and counted.
[[gnu::noinline]] bool ValidateBoundByLookup(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                             const AccelerationStructureState& as, const char* vuid,
                                             const char* field) {
  const std::shared_ptr<const BufferState> buffer = BufferOfStructure(ctx.state, as);
  if (!buffer || (buffer->create_flags & VK_BUFFER_CREATE_SPARSE_BINDING_BIT)) {
    CountUnknownState(ctx);
    return false;
  }
  if (buffer->bound) return false;
  return ReportBuild(
      ctx, cmd, i, vuid, [&](std::string&) { return InfoLocation(cmd, i).Field(field); },
      "(0x{:x}) was created on VkBuffer 0x{:x}, which is not bound to device memory (no "
      "vkBindBufferMemory or vkBindBufferMemory2 for it succeeded).",
      reinterpret_cast<uint64_t>(as.handle), reinterpret_cast<uint64_t>(as.buffer));
}

inline bool ValidateBound(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                          const AccelerationStructureState& as, const char* vuid, const char* field) {
  if (as.buffer_was_bound) return false;  // bound before the structure was created: no lookup (inline, no call)
  return ValidateBoundByLookup(ctx, cmd, i, as, vuid, field);
}

bool ValidateInfoHandles(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  bool skip = false;
  const AccelerationStructureState* dst = r.dst;
  // A handle the layer does not know may be a structure whose shadow record its allocation failed to make
  // (failure_counters.h): then unknown, skipped and counted, not reported.
  const bool structures_incomplete = ctx.state.failures().structures_incomplete.load(std::memory_order_relaxed);
  if (!dst && info.dstAccelerationStructure != VK_NULL_HANDLE && structures_incomplete) {
    CountUnknownState(ctx);
  } else if (!dst) {
    skip |= ReportInvalidDestination(ctx, cmd, i);
  } else {
    skip |= ValidateDestinationType(ctx, cmd, i, *dst);
    skip |= ValidateMotion(ctx, cmd, i, *dst);
    if (!cmd.is_host()) skip |= ValidateBound(ctx, cmd, i, *dst, "pInfos-03707", "dstAccelerationStructure");
  }
  if (info.srcAccelerationStructure != VK_NULL_HANDLE) {
    const AccelerationStructureState* src = r.src;
    if (!src && structures_incomplete) {
      CountUnknownState(ctx);
    } else if (!src) {
      skip |= ReportInvalidSource(ctx, cmd, i);
    } else if (!cmd.is_host() && info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR) {
      skip |= ValidateBound(ctx, cmd, i, *src, "pInfos-03708", "srcAccelerationStructure");
    }
  }
  return skip;
}

// A destination handle and the index of its info, sorted by handle.
using DstEntry = std::pair<VkAccelerationStructureKHR, uint32_t>;

[[gnu::cold, gnu::noinline]] bool ReportSharedDestination(const CheckContext& ctx, const BuildCommand& cmd,
                                                          uint32_t first, uint32_t second) {
  return ReportBuild(ctx, cmd, second, "dstAccelerationStructure-03698",
                     [&](std::string&) { return InfoLocation(cmd, second).Field("dstAccelerationStructure"); },
                     "(0x{:x}) is also the dstAccelerationStructure of pInfos[{}]: one command must not build the "
                     "same acceleration structure twice.",
                     reinterpret_cast<uint64_t>(cmd.infos[second].dstAccelerationStructure), first);
}

[[gnu::cold, gnu::noinline]] bool ReportSourceIsOtherDestination(const CheckContext& ctx, const BuildCommand& cmd,
                                                                 uint32_t i, uint32_t other) {
  return ReportBuild(ctx, cmd, i, "pInfos-03403",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("srcAccelerationStructure"); },
                     "(0x{:x}) is the dstAccelerationStructure of pInfos[{}]: a structure one info reads must not be "
                     "written by another info of the same command (an in-place update names it as its own source "
                     "and destination, in one info).",
                     reinterpret_cast<uint64_t>(cmd.infos[i].srcAccelerationStructure), other);
}

// Whether no two infos share a destination and no info's source is any info's destination (in-place updates
// included): then neither rule below has anything to say. One pass over a small open-addressing set on the
// stack; a hit on either question sends the command to the rules, which find and report exactly what they
// always do.
bool HandlesCertainlyDistinct(const BuildCommand& cmd) {
  constexpr uint32_t kSlots = 2 * kFewInfos;  // at most half full
  static_assert(kSlots == 32, "slot_of takes the top 5 bits of the hash");
  VkAccelerationStructureKHR set[kSlots] = {};
  const auto slot_of = [](VkAccelerationStructureKHR h) {
    return static_cast<uint32_t>((reinterpret_cast<uint64_t>(h) * 0x9e3779b97f4a7c15ull) >> 59);
  };
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureKHR dst = cmd.infos[i].dstAccelerationStructure;
    if (!dst) continue;
    uint32_t k = slot_of(dst);
    for (; set[k]; k = (k + 1) & (kSlots - 1)) {
      if (set[k] == dst) return false;
    }
    set[k] = dst;
  }
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureKHR src = cmd.infos[i].srcAccelerationStructure;
    if (!src) continue;
    for (uint32_t k = slot_of(src); set[k]; k = (k + 1) & (kSlots - 1)) {
      if (set[k] == src) return false;
    }
  }
  return true;
}

// dstAccelerationStructure-03698 and pInfos-03403 for a few infos: comparing every pair is cheaper than
// sorting. Reports the same pairs as the sorted version (each against the lowest other index).
bool ValidateDistinctHandlesFew(const CheckContext& ctx, const BuildCommand& cmd) {
  if (HandlesCertainlyDistinct(cmd)) return false;
  bool skip = false;
  for (uint32_t k = 1; k < cmd.info_count; ++k) {
    const VkAccelerationStructureKHR dst = cmd.infos[k].dstAccelerationStructure;
    if (!dst) continue;
    for (uint32_t m = 0; m < k; ++m) {
      if (cmd.infos[m].dstAccelerationStructure != dst) continue;
      skip |= ReportSharedDestination(ctx, cmd, m, k);
      break;
    }
  }
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureKHR src = cmd.infos[i].srcAccelerationStructure;
    if (!src) continue;
    for (uint32_t j = 0; j < cmd.info_count; ++j) {
      if (j == i || cmd.infos[j].dstAccelerationStructure != src) continue;
      skip |= ReportSourceIsOtherDestination(ctx, cmd, i, j);
      break;
    }
  }
  return skip;
}

// dstAccelerationStructure-03698 and pInfos-03403 for many infos, by sorting the destinations once.
bool ValidateDistinctHandlesMany(const CheckContext& ctx, const BuildCommand& cmd) {
  thread_local std::vector<DstEntry> sorted;  // reused: no allocation once it has grown
  sorted.clear();
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    if (cmd.infos[i].dstAccelerationStructure) sorted.emplace_back(cmd.infos[i].dstAccelerationStructure, i);
  }
  std::sort(sorted.begin(), sorted.end());
  bool skip = false;
  for (size_t k = 1; k < sorted.size(); ++k) {
    if (sorted[k].first != sorted[k - 1].first) continue;
    // Report each later info against the first of its run (lowest index: the pairs are sorted).
    size_t first = k - 1;
    while (first > 0 && sorted[first - 1].first == sorted[k].first) --first;
    skip |= ReportSharedDestination(ctx, cmd, sorted[first].second, sorted[k].second);
  }
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureKHR src = cmd.infos[i].srcAccelerationStructure;
    if (!src) continue;
    auto it = std::lower_bound(sorted.begin(), sorted.end(), DstEntry{src, 0});
    for (; it != sorted.end() && it->first == src; ++it) {
      if (it->second == i) continue;  // the same info: an in-place update
      skip |= ReportSourceIsOtherDestination(ctx, cmd, i, it->second);
      break;  // once per source
    }
  }
  return skip;
}

}  // namespace

namespace {

// Whether ValidateInfoHandles certainly has nothing to report or count for pInfos[i]: a live destination of the
// build's type (or GENERIC), bound before it was created (or a host build), created for motion exactly when the build
// is a motion build, and no source, or a live one that needs
// no binding test or was bound before it was created. Only compares, so that a loop over clean infos needs no call
// and no stack frame; any other info takes the rules, which report exactly as before.
inline bool InfoHandlesClean(const BuildCommand& cmd, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                             const ResolvedInfo& r) {
  const AccelerationStructureState* dst = r.dst;
  if (!dst) return false;
  if ((info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR ||
       info.type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) &&
      dst->type != info.type && dst->type != VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR) {
    return false;
  }
  if (!cmd.is_host() && !dst->buffer_was_bound) return false;
  // Motion (04927 / 04928): the build's motion flag and the destination's motion creation flag agree.
  if (((info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0) !=
      ((dst->create_flags & VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV) != 0)) {
    return false;
  }
  if (info.srcAccelerationStructure == VK_NULL_HANDLE) return true;
  if (!r.src) return false;
  return cmd.is_host() || info.mode != VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR || r.src->buffer_was_bound;
}

// The per-info rules from pInfos[first] on, the first info that is not certainly clean, then the rules between
// infos (out of line).
[[gnu::noinline]] bool ValidateInfosFrom(const CheckContext& ctx, const BuildCommand& cmd,
                                         const ResolvedBuild& resolved, uint32_t first) {
  bool skip = false;
  for (uint32_t i = first; i < cmd.info_count; ++i) {
    const ResolvedInfo& r = resolved.info(i);
    if (!InfoHandlesClean(cmd, cmd.infos[i], r)) skip |= ValidateInfoHandles(ctx, cmd, i, r);
  }
  if (cmd.info_count > kFewInfos) {
    skip |= ValidateDistinctHandlesMany(ctx, cmd);
  } else if (cmd.info_count > 1) {
    skip |= ValidateDistinctHandlesFew(ctx, cmd);
  }
  return skip;
}

}  // namespace

bool ValidateBuildHandles(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  if (!cmd.infos) return false;
  // The clean infos first, by compares only: a one-info command of a clean info needs no call and no stack frame.
  uint32_t i = 0;
  while (i < cmd.info_count && InfoHandlesClean(cmd, cmd.infos[i], resolved.info(i))) ++i;
  if (i == cmd.info_count && cmd.info_count <= 1) return false;
  return ValidateInfosFrom(ctx, cmd, resolved, i);
}

}  // namespace asval
