#pragma once
// Which bytes a build reads, geometry by geometry (execution-time capture, issue 12): exactly the ranges the
// specification says a build consumes, from where it starts reading, and the geometry's parameters rewritten for
// bytes that start there. One plan for both kinds of capture: device builds copy the ranges with vkCmdCopyBuffer
// when they execute (layer/capture), host builds copy them from host memory when they are called
// (host_capture.h).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <limits>
#include <vector>

#include "capture_log.h"

namespace asval {

inline constexpr VkDeviceSize kNoBytes = std::numeric_limits<VkDeviceSize>::max();
// Saturating arithmetic on sizes and addresses (an absurd range saturates and is then not found in any buffer).
inline VkDeviceSize SaturatingAddBytes(VkDeviceSize a, VkDeviceSize b) { return a > kNoBytes - b ? kNoBytes : a + b; }
inline VkDeviceSize SaturatingMulBytes(VkDeviceSize a, VkDeviceSize b) {
  return b != 0 && a > kNoBytes / b ? kNoBytes : a * b;
}

// Whether an info's activity is what an update rule compares: it is an update, or the source a later update may
// have (ALLOW_UPDATE).
inline bool ActivityNeededForUpdates(const VkAccelerationStructureBuildGeometryInfoKHR& info) {
  return info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR ||
         (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR) != 0;
}

// One range a build reads: from an address (a device address, or a host pointer for host builds) into the
// capture log.
struct CaptureSource {
  uint64_t address;
  VkDeviceSize size;
  CapturedBytes* into;
  bool optional = false;  // not needed for the rules (a transform, for the warnings): skipped when not copyable
};

// The ranges geometry g reads into `sources` (appended), its captured parameters into *out. `host`: the
// geometry's addresses are host pointers (vkBuildAccelerationStructuresKHR). False when the geometry is not
// captured, and *why says why: a kind or format the builder does not read (kGeometryNotCaptured), a null address
// with primitives to read (kNullInput). `motion`: the build sets VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV, so a
// triangles geometry's VkAccelerationStructureGeometryMotionTrianglesDataNV (its vertices at time 1) is read too; a
// motion build's triangles without one are not captured (kGeometryNotCaptured).
bool PlanCapturedGeometry(const VkAccelerationStructureGeometryKHR& g,
                          const VkAccelerationStructureBuildRangeInfoKHR& r, bool host, CapturedGeometry* out,
                          std::vector<CaptureSource>& sources, CaptureSkip* why, bool motion = false);

}  // namespace asval
