#pragma once
// The one test of a build info's geometry count against the device's maxGeometryCount, shared by every walk of an
// info's geometries: the checks, the size lookup, the capture and the history recorder.
#include <vulkan/vulkan.h>

#include <cstdint>

namespace asval {

// Whether a build info's geometries stay within maxGeometryCount (bottom level; a limit of 0 was not reported).
// Past it the build is invalid as a whole (type-03793) and its arrays may be shorter than its count: nothing may
// walk them, neither a signature (Find) nor the driver's size query.
inline bool GeometryCountWithinLimit(const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                     uint64_t max_geometry_count) {
  return info.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR || max_geometry_count == 0 ||
         info.geometryCount <= max_geometry_count;
}

}  // namespace asval
