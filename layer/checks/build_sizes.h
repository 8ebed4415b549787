#pragma once
// The sizes the driver reports for one info of a build command, and the rules that compare with them
// (family "addresses"):
//   pInfos-10126 (older: 03675)   direct and host builds: dstAccelerationStructure was created at least as
//                                 large as accelerationStructureSize for this geometry and these counts
//   pInfos-03652                  indirect builds: the same, with ppMaxPrimitiveCounts[i] as the counts
//   pInfos-03801                  an instance geometry's count is at most maxInstanceCount
// The scratch rules that use the same sizes are in build_addresses.h.
#include <optional>

#include "build_command.h"
#include "build_memory_pass.h"
#include "build_size_cache.h"
#include "check_context.h"

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

// The sizes of pInfos[i] (cache, else one driver query). nullopt, counted as a skip for unknown state, when
// they cannot be known: counts not given, or the query would not be valid (see SizeQueryIsValid).
std::optional<BuildSizes> SizesOfInfo(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i);

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

// pInfos-10126 / pInfos-03652 and pInfos-03801 for pInfos[i], all three commands.
bool ValidateInfoSizes(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const InfoResolution& r);

}  // namespace asval
