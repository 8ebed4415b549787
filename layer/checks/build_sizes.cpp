#include "build_sizes.h"

#include <cstddef>

#include "asval/vertex_formats.h"
#include "build_report.h"
#include "rule_judge.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

// Flag bits and pNext chains go to the size query as the app gave them, those newer than the layer's headers
// included (ALLOW_DATA_ACCESS of VK_KHR_ray_tracing_position_fetch, micromap and motion structures, ...): the query
// takes the same info as the build, and the driver that accepts the app's build knows them. A build with a chain is
// queried every time, never cached (BuildSignature::Cacheable: the layer cannot compare unknown structures).
constexpr VkBuildAccelerationStructureFlagsKHR kFastBoth =
    VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
constexpr VkDeviceSize kMaxStride = 0xffffffffull;

// Alignment unit (component size, or size of a packed format) of the acceleration-structure vertex formats
// the shared table decodes, the formats the query accepts; 0 for others. The device's format features
// decide whether the format is usable at all.
uint32_t VertexComponentBytes(VkFormat format) {
  const VertexFormatInfo& facts = VertexFormatFacts(format);
  return facts.decodable ? facts.componentBytes : 0;
}

bool TrianglesQueryable(const DeviceState& state, const VkAccelerationStructureGeometryTrianglesDataKHR& t) {
  if (t.sType != VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR) return false;
  const uint32_t component = VertexComponentBytes(t.vertexFormat);
  if (component == 0 || t.vertexStride % component != 0 || t.vertexStride > kMaxStride) return false;
  if (t.indexType != VK_INDEX_TYPE_NONE_KHR && t.indexType != VK_INDEX_TYPE_UINT16 &&
      t.indexType != VK_INDEX_TYPE_UINT32) {
    return false;
  }
  const std::optional<VkFormatFeatureFlags> features = state.format_features.BufferFeatures(t.vertexFormat);
  return features && (*features & VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR);
}

bool GeometryQueryable(const DeviceState& state, const VkAccelerationStructureGeometryKHR* g,
                       VkGeometryTypeKHR expected) {
  if (!g || g->sType != VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR) return false;
  if (g->geometryType != expected) return false;
  switch (g->geometryType) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
      return TrianglesQueryable(state, g->geometry.triangles);
    case VK_GEOMETRY_TYPE_AABBS_KHR: {
      const VkAccelerationStructureGeometryAabbsDataKHR& a = g->geometry.aabbs;
      return a.sType == VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR &&
             a.stride % 8 == 0 && a.stride <= kMaxStride;
    }
    case VK_GEOMETRY_TYPE_INSTANCES_KHR: {
      const VkAccelerationStructureGeometryInstancesDataKHR& d = g->geometry.instances;
      return d.sType == VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR &&
             (d.arrayOfPointers == VK_TRUE || d.arrayOfPointers == VK_FALSE);
    }
    default:
      return false;
  }
}

// Out of line: walked only for infos the geometry pass flagged.
[[gnu::noinline]] bool ValidateInstanceCounts(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (!GeometriesWalkable(ctx, info)) return false;  // past maxGeometryCount: type-03793 says it, nothing is walked
  if (cmd.is_indirect() ? !cmd.max_primitive_counts || !cmd.max_primitive_counts[i] : !cmd.ranges || !cmd.ranges[i]) {
    return false;  // counts not given: another rule's business
  }
  ReportingJudge judge{ctx};
  GeometryFactsReader facts(ctx.state);
  bool skip = false;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
    if (g) skip |= InstanceCountRule(ctx, cmd, i, j, facts.Read(*g), judge);
  }
  return skip;
}

[[gnu::cold, gnu::noinline]] bool ReportDestinationTooSmall(const CheckContext& ctx, const BuildCommand& cmd,
                                                            uint32_t i, VkDeviceSize created, VkDeviceSize needed) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  std::string counts;
  for (uint32_t j = 0; j < info.geometryCount && j < 8; ++j) {
    counts += fmt::format("{}{}", j ? ", " : "",
                          cmd.is_indirect() ? cmd.max_primitive_counts[i][j] : cmd.ranges[i][j].primitiveCount);
  }
  if (info.geometryCount > 8) counts += ", ...";
  return ReportBuild(ctx, cmd, i, cmd.is_indirect() ? "pInfos-03652" : "pInfos-10126",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("dstAccelerationStructure"); },
                     "(VkAccelerationStructureKHR 0x{:x}) was created with size {}, but "
                     "vkGetAccelerationStructureBuildSizesKHR reports accelerationStructureSize {} for this build "
                     "({}, {} geometr{}, {} [{}]); it is {} bytes short.",
                     reinterpret_cast<uint64_t>(info.dstAccelerationStructure), created, needed,
                     string_VkAccelerationStructureTypeKHR(info.type), info.geometryCount,
                     info.geometryCount == 1 ? "y" : "ies",
                     cmd.is_indirect() ? "ppMaxPrimitiveCounts" : "primitive counts", counts, needed - created);
}

bool ValidateDestinationSize(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r) {
  if (!r.sizes) return false;  // counted by ValidateBuildMemory
  if (!r.dst) {
    CountUnknownState(ctx);  // not a live structure: dstAccelerationStructure-03800 says so
    return false;
  }
  if (r.dst->size >= r.sizes->acceleration_structure_size) return false;
  if (cmd.infos[i].mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR) {
    // An update may write a compacted structure, smaller than the build size (the rule's second branch):
    // whether dst came from a compacting copy is history the layer does not have here.
    CountUnknownState(ctx);
    return false;
  }
  return ReportDestinationTooSmall(ctx, cmd, i, r.dst->size, r.sizes->acceleration_structure_size);
}

}  // namespace

namespace {

// SignatureOfInfo, inline in SizesOfInfo (the resolution's lookup of every info).
[[gnu::always_inline]] inline bool SignatureOf(const BuildCommand& cmd, uint32_t i, BuildSignature* out) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  out->build_type =
      cmd.is_host() ? VK_ACCELERATION_STRUCTURE_BUILD_TYPE_HOST_KHR : VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR;
  out->info = &info;
  if (cmd.is_indirect()) {
    if (!cmd.max_primitive_counts || (info.geometryCount != 0 && !cmd.max_primitive_counts[i])) return false;
    out->counts = cmd.max_primitive_counts[i];
    out->count_stride = sizeof(uint32_t);
    return true;
  }
  if (!cmd.ranges || (info.geometryCount != 0 && !cmd.ranges[i])) return false;
  // primitiveCount is the first member of VkAccelerationStructureBuildRangeInfoKHR.
  static_assert(offsetof(VkAccelerationStructureBuildRangeInfoKHR, primitiveCount) == 0);
  out->counts = cmd.ranges[i] ? &cmd.ranges[i][0].primitiveCount : nullptr;
  out->count_stride = sizeof(VkAccelerationStructureBuildRangeInfoKHR);
  return true;
}

}  // namespace

bool SignatureOfInfo(const BuildCommand& cmd, uint32_t i, BuildSignature* out) { return SignatureOf(cmd, i, out); }

bool SizeQueryIsValid(const DeviceState& state, const BuildSignature& signature) {
  const DeviceFeatures& f = state.features;
  // vkGetAccelerationStructureBuildSizesKHR-accelerationStructure-08933, and rayTracingPipeline-03617 as the
  // Khronos layer 1.3.239 reads it (rayQuery or rayTracingPipeline).
  if (!f.acceleration_structure || !(f.ray_query || f.ray_tracing_pipeline) || !state.build_sizes.can_query()) {
    return false;
  }
  const VkAccelerationStructureBuildGeometryInfoKHR& info = *signature.info;
  if (info.sType != VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR) return false;
  if ((info.flags & kFastBoth) == kFastBoth) return false;
  if (info.geometryCount != 0 && (info.pGeometries == nullptr) == (info.ppGeometries == nullptr)) return false;
  const VkPhysicalDeviceAccelerationStructurePropertiesKHR& limits = state.properties.acceleration_structure;
  if (info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
    return info.geometryCount == 1 &&
           GeometryQueryable(state, signature.Geometry(0), VK_GEOMETRY_TYPE_INSTANCES_KHR) &&
           signature.Count(0) <= limits.maxInstanceCount;
  }
  if (info.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR || info.geometryCount > limits.maxGeometryCount) {
    return false;
  }
  if (info.geometryCount == 0) return true;
  const VkAccelerationStructureGeometryKHR* first = signature.Geometry(0);
  if (!first || (first->geometryType != VK_GEOMETRY_TYPE_TRIANGLES_KHR &&
                 first->geometryType != VK_GEOMETRY_TYPE_AABBS_KHR)) {
    return false;
  }
  uint64_t primitives = 0;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    if (!GeometryQueryable(state, signature.Geometry(j), first->geometryType)) return false;
    primitives += signature.Count(j);
  }
  return primitives <= limits.maxPrimitiveCount;
}

std::optional<BuildSizes> SizesOfInfo(const DeviceState& state, const BuildCommand& cmd, uint32_t i,
                                      BuildSizeCache::ThreadTable* table) {
  if (!GeometryCountWithinLimit(cmd.infos[i], state.properties.acceleration_structure.maxGeometryCount)) {
    return std::nullopt;  // type-03793 says it; the arrays may be shorter than the count
  }
  BuildSignature signature;
  BuildSizes sizes;
  if (SignatureOf(cmd, i, &signature)) {
    const bool found = table ? state.build_sizes.Find(signature, &sizes, *table) : state.build_sizes.Find(signature, &sizes);
    if (found) return sizes;
    if (SizeQueryIsValid(state, signature)) {
      if (std::optional<BuildSizes> queried = state.build_sizes.Query(signature)) return queried;
    }
  }
  return std::nullopt;
}

// pInfos-03801: instance counts (primitive counts of instance geometries) within maxInstanceCount.
bool ReportInstanceCount(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, uint32_t count,
                         uint64_t limit) {
  return ReportBuild(ctx, cmd, i, "pInfos-03801",
                     [&](std::string& storage) {
                       if (cmd.is_indirect()) {
                         storage = fmt::format("ppMaxPrimitiveCounts[{}][{}]", i, j);
                       } else {
                         storage = fmt::format("ppBuildRangeInfos[{}][{}].primitiveCount", i, j);
                       }
                       return cmd.Root().Field(storage.c_str());
                     },
                     "({}) is greater than VkPhysicalDeviceAccelerationStructurePropertiesKHR::maxInstanceCount ({}); "
                     "pInfos[{}].{}[{}] is a VK_GEOMETRY_TYPE_INSTANCES_KHR geometry.",
                     count, limit, i, cmd.infos[i].pGeometries ? "pGeometries" : "ppGeometries", j);
}

bool ValidateInfoSizes(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r) {
  if (InfoSizesClean(r)) return false;
  // Infos in which the command's geometry pass found nothing for pInfos-03801 are not walked again.
  const bool counts = (r.walks & kWalkInstanceCounts) && ValidateInstanceCounts(ctx, cmd, i);
  return counts | ValidateDestinationSize(ctx, cmd, i, r);
}

}  // namespace asval
