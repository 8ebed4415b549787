#pragma once
// How the layer learns the driver's sizes for one info of a build command (cache, else one valid query): used
// by the command's resolution (resolved_build.h) and the host family. Defined in build_sizes.cpp, next to the
// rules that compare with the sizes.
#include <optional>

#include "build_command.h"
#include "build_size_cache.h"
#include "device_state.h"

namespace asval {

// The signature of pInfos[i] for the size query: its build type and counts (ppBuildRangeInfos[i][j].
// primitiveCount, or ppMaxPrimitiveCounts[i][j] for indirect builds). False when the counts are not given.
bool SignatureOfInfo(const BuildCommand& cmd, uint32_t i, BuildSignature* out);

// True when vkGetAccelerationStructureBuildSizesKHR may be asked about this build without breaking one of its
// own rules (the layer's calls must be valid): the device enabled accelerationStructure and rayQuery or
// rayTracingPipeline, the info is structurally valid as far as the layer's headers know it, the vertex
// formats support acceleration-structure vertex buffers, and the counts are within the device's limits.
// Runs only on a cache miss.
bool SizeQueryIsValid(const DeviceState& state, const BuildSignature& signature);

// The sizes of pInfos[i] (cache, else one driver query). nullopt when they cannot be known: counts not given,
// or the query would not be valid (see SizeQueryIsValid); the family that needed them counts the skip. table:
// the caller's per-thread table of recent hits (null: the cache's own thread_local one).
std::optional<BuildSizes> SizesOfInfo(const DeviceState& state, const BuildCommand& cmd, uint32_t i,
                                      BuildSizeCache::ThreadTable* table = nullptr);

// True when pInfos[a] and pInfos[b] certainly have the same signature, without reading it: no extension chain,
// the same header fields, and the very same geometry and count arrays (the app cannot change them during
// the call). Then pInfos[b]'s sizes are pInfos[a]'s.
inline bool SameSignatureArrays(const BuildCommand& cmd, uint32_t a, uint32_t b) {
  const VkAccelerationStructureBuildGeometryInfoKHR& x = cmd.infos[a];
  const VkAccelerationStructureBuildGeometryInfoKHR& y = cmd.infos[b];
  if (x.pNext || y.pNext || x.sType != y.sType || x.type != y.type || x.flags != y.flags ||
      x.geometryCount != y.geometryCount || x.pGeometries != y.pGeometries || x.ppGeometries != y.ppGeometries) {
    return false;
  }
  if (cmd.is_indirect()) return cmd.max_primitive_counts && cmd.max_primitive_counts[a] == cmd.max_primitive_counts[b];
  return cmd.ranges && cmd.ranges[a] == cmd.ranges[b];
}

}  // namespace asval
