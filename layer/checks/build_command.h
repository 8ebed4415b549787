#pragma once
// One normalized view of the three build commands (vkCmdBuildAccelerationStructuresKHR, its Indirect
// variant and the host vkBuildAccelerationStructuresKHR), so that each rule family is written once and
// applied to all three. Built on the stack by the hook; no copies of the app's arrays.
#include <vulkan/vulkan.h>

#include <string>

#include "location.h"

namespace asval {

class CaptureLog;

enum class BuildCommandKind { kCmdBuild, kCmdBuildIndirect, kHostBuild };

struct BuildCommand {
  BuildCommandKind kind;
  const char* function;  // "vkCmdBuildAccelerationStructuresKHR", ... (also the Location root)
  VkDevice device = VK_NULL_HANDLE;
  VkCommandBuffer command_buffer = VK_NULL_HANDLE;               // device commands
  VkDeferredOperationKHR deferred_operation = VK_NULL_HANDLE;  // host builds
  uint32_t info_count = 0;
  const VkAccelerationStructureBuildGeometryInfoKHR* infos = nullptr;
  // Direct and host builds: ranges[i][j] for info i, geometry j.
  const VkAccelerationStructureBuildRangeInfoKHR* const* ranges = nullptr;
  // Indirect builds: where the ranges live on the device, and the app's upper bounds for the counts.
  const VkDeviceAddress* indirect_addresses = nullptr;
  const uint32_t* indirect_strides = nullptr;
  const uint32_t* const* max_primitive_counts = nullptr;
  // Host builds: the inputs captured when called (host_capture.h), for the activity rules; null when none.
  CaptureLog* host_capture = nullptr;
  const uint32_t* host_captured = nullptr;  // per info: its index in host_capture->infos plus one, or 0

  bool is_host() const { return kind == BuildCommandKind::kHostBuild; }
  bool is_indirect() const { return kind == BuildCommandKind::kCmdBuildIndirect; }
  Location Root() const { return Location(function); }

  // "VUID-<function>-<suffix>", e.g. Vuid("pInfos-03710"). Allocates: call it only when reporting.
  std::string Vuid(const char* suffix) const { return std::string("VUID-") + function + "-" + suffix; }

  // The primitive count of geometry j of info i, when it is known on the host (not for indirect builds,
  // whose counts live on the device; their ppMaxPrimitiveCounts bound is separate).
  bool PrimitiveCount(uint32_t i, uint32_t j, uint32_t* count) const {
    if (!ranges || !ranges[i]) return false;
    *count = ranges[i][j].primitiveCount;
    return true;
  }
};

// Geometry j of a build info, whichever of pGeometries / ppGeometries the app used (null if neither).
inline const VkAccelerationStructureGeometryKHR* GeometryAt(const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                                           uint32_t j) {
  if (info.pGeometries) return &info.pGeometries[j];
  if (info.ppGeometries) return info.ppGeometries[j];
  return nullptr;
}

}  // namespace asval
