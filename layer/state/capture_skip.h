#pragma once
// Why a build info that a rule needed was not captured (execution-time capture, issue 12; issue 26: say why). Each
// reason has its own count (CaptureCounters::infos_not_captured) and a stable snake_case name, the one the
// ASVAL-History-Summary text, the JSON report's "capture_skipped" field and scripts/asval-run show, and
// docs/capture.md explains. An info counts once, under the first reason that stopped it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace asval {

enum class CaptureSkip : uint8_t {
  // The recording's captures (a host call's, for host builds) would have gone past capture_budget_mb.
  kOverBudget = 0,
  // A range the build reads lies in no live, bound buffer the layer knows of (from end to end).
  kUnknownAddress,
  // The range lies in a buffer the layer knows, but it had nothing to copy it through: its own buffer over that
  // memory could not be made (memory_aliases.h), or a dedicated allocation's buffer was not made copyable.
  kBufferNotCopyable,
  // A geometry kind or format the capture does not read: motion instances (VK_NV_ray_tracing_motion_blur), a
  // vertex format or index type the reference builder does not decode, a geometry type it does not know.
  kGeometryNotCaptured,
  // The info gives nothing to read where it has primitives: no geometries or range infos, a null element of
  // ppGeometries, a null data address (the app's error, reported by its own rule).
  kNullInput,
  // The layer's capture memory could not be had (its slab's vkCreateBuffer / vkAllocateMemory / vkMapMemory, or a
  // host build's heap block, failed), or its dispatch had no room left for the geometry's job.
  kCaptureMemoryFailed,
  // An allocation of the layer's own failed while it planned the command's captures: the command captured nothing.
  kAllocationFailed,
};

inline constexpr std::size_t kCaptureSkipCount = 7;

// The names, in the enum's order (one place: the summary, the JSON field and the tests read them from here).
inline constexpr std::array<std::string_view, kCaptureSkipCount> kCaptureSkipNames = {
    "over_capture_budget_mb", "unknown_address",         "buffer_not_copyable", "geometry_not_captured",
    "null_input",             "capture_memory_failed", "allocation_failed",
};

inline constexpr std::size_t SkipIndex(CaptureSkip why) { return static_cast<std::size_t>(why); }
inline constexpr std::string_view NameOf(CaptureSkip why) { return kCaptureSkipNames[SkipIndex(why)]; }
static_assert(SkipIndex(CaptureSkip::kAllocationFailed) + 1 == kCaptureSkipCount, "a name for every reason");

}  // namespace asval
