#include "build_structure.h"

#include "build_report.h"
#include "rule_judge.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

constexpr const char* kInfoVuid = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-";

std::string InfoVuid(const char* suffix) { return std::string(kInfoVuid) + suffix; }

// The per-info rules of this file, named for their reporting half: the clean path passes only this and the
// indices, so that it keeps no message pieces (strings, lambdas) in its own frame.
enum class InfoRule { kGeneric, kFastBoth, kMicromapBoth, kGeometryArrays, kTopCount, kBottomCount };

[[gnu::cold, gnu::noinline]] bool ReportInfoRule(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                 InfoRule rule) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  switch (rule) {
    case InfoRule::kGeneric:
      return ReportBuild(ctx, cmd, i, InfoVuid("type-03654"),
                         [&](std::string&) { return InfoLocation(cmd, i).Field("type"); },
                         "is VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR: a build must say whether it is top- or "
                         "bottom-level.");
    case InfoRule::kFastBoth:
      return ReportBuild(ctx, cmd, i, InfoVuid("flags-03796"),
                         [&](std::string&) { return InfoLocation(cmd, i).Field("flags"); },
                         "(0x{:x}) has both VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR and "
                         "VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR set.",
                         info.flags);
    case InfoRule::kMicromapBoth:
      return ReportBuild(ctx, cmd, i, InfoVuid("flags-07334"),
                         [&](std::string&) { return InfoLocation(cmd, i).Field("flags"); },
                         "(0x{:x}) has both VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_BIT_EXT and "
                         "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_DATA_UPDATE_BIT_EXT set.",
                         info.flags);
    case InfoRule::kGeometryArrays:
      return ReportBuild(ctx, cmd, i, InfoVuid("pGeometries-03788"),
                         [&](std::string&) { return InfoLocation(cmd, i).Field("pGeometries"); },
                         "and ppGeometries are {}, but geometryCount is {}: exactly one of them must point to the "
                         "geometries.",
                         info.pGeometries ? "both non-NULL" : "both NULL", info.geometryCount);
    case InfoRule::kTopCount:
      return ReportBuild(ctx, cmd, i, InfoVuid("type-03790"),
                         [&](std::string&) { return InfoLocation(cmd, i).Field("geometryCount"); },
                         "({}) is not 1, but pInfos[{}].type is VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR.",
                         info.geometryCount, i);
    case InfoRule::kBottomCount:
      return ReportBuild(ctx, cmd, i, InfoVuid("type-03793"),
                         [&](std::string&) { return InfoLocation(cmd, i).Field("geometryCount"); },
                         "({}) is greater than VkPhysicalDeviceAccelerationStructurePropertiesKHR::maxGeometryCount ({}) "
                         "for a bottom-level build.",
                         info.geometryCount, uint64_t{ctx.state.properties.acceleration_structure.maxGeometryCount});
  }
  return false;
}

bool ValidateFlags(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  const VkBuildAccelerationStructureFlagsKHR flags = cmd.infos[i].flags;
  bool skip = false;
  constexpr VkBuildAccelerationStructureFlagsKHR kFastBoth =
      VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  constexpr VkBuildAccelerationStructureFlagsKHR kMicromapBoth =
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT |
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_DATA_UPDATE_EXT;
  if ((flags & kFastBoth) == kFastBoth) skip |= ReportInfoRule(ctx, cmd, i, InfoRule::kFastBoth);
  if ((flags & kMicromapBoth) == kMicromapBoth) skip |= ReportInfoRule(ctx, cmd, i, InfoRule::kMicromapBoth);
  return skip;
}

// type-03793 (bottom level: geometryCount <= maxGeometryCount) and type-03790 (top level: exactly one).
bool ValidateGeometryCount(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR && info.geometryCount != 1) {
    return ReportInfoRule(ctx, cmd, i, InfoRule::kTopCount);
  }
  if (info.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) return false;
  const uint64_t limit = ctx.state.properties.acceleration_structure.maxGeometryCount;
  if (limit == 0) {
    CountUnknownState(ctx);  // the driver's limit is unknown (no properties2)
    return false;
  }
  if (info.geometryCount <= limit) return false;
  return ReportInfoRule(ctx, cmd, i, InfoRule::kBottomCount);
}

bool ValidateGeometryArrays(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (info.geometryCount == 0 || (info.pGeometries == nullptr) != (info.ppGeometries == nullptr)) return false;
  return ReportInfoRule(ctx, cmd, i, InfoRule::kGeometryArrays);
}

// The geometries of one info: the type rules (type-03789, 03791, 03792), each geometry's data rules, and
// the primitive totals of a bottom-level build (StructureGeometryRules, build_structure.h).
// Out of line: walked only for infos the geometry pass flagged.
[[gnu::noinline]] bool ValidateGeometries(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  if (!GeometriesWalkable(ctx, info)) return false;
  ReportingJudge judge{ctx};
  GeometryFactsReader facts(ctx.state);
  StructureGeometryRules<ReportingJudge> rules(ctx, cmd, i);
  bool skip = false;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* geometry = GeometryAt(info, j);
    if (geometry) skip |= rules.Geometry(j, facts.Read(*geometry), judge);
  }
  skip |= rules.Finish(judge);
  return skip;
}

bool ValidateInfoStructure(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  bool skip = false;
  if (info.type == VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR) skip |= ReportInfoRule(ctx, cmd, i, InfoRule::kGeneric);
  skip |= ValidateFlags(ctx, cmd, i);
  skip |= ValidateGeometryArrays(ctx, cmd, i);
  skip |= ValidateGeometryCount(ctx, cmd, i);
  // Geometries in which the command's geometry pass found nothing for this family are not walked again.
  if (r.walks & kWalkStructure) skip |= ValidateGeometries(ctx, cmd, i);
  return skip;
}

}  // namespace

bool ReportGeometryType(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j, const char* suffix,
                        const char* why) {
  const VkGeometryTypeKHR type = GeometryAt(cmd.infos[i], j)->geometryType;
  return ReportBuild(ctx, cmd, i, InfoVuid(suffix),
                     [&](std::string&) { return GeometryLocation(cmd, i, j).Field("geometryType"); }, "({}) {}",
                     string_VkGeometryTypeKHR(type), why);
}

bool ReportPrimitiveTotal(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, bool aabbs, uint64_t total,
                          uint64_t limit) {
  if (aabbs) {
    return ReportBuild(ctx, cmd, i, InfoVuid("type-03794"), [&](std::string&) { return InfoLocation(cmd, i); },
                       "is a bottom-level build of {} AABBs in all geometries (the sum of "
                       "ppBuildRangeInfos[{}][j].primitiveCount), more than "
                       "VkPhysicalDeviceAccelerationStructurePropertiesKHR::maxPrimitiveCount ({}).",
                       total, i, limit);
  }
  return ReportBuild(ctx, cmd, i, InfoVuid("type-03795"), [&](std::string&) { return InfoLocation(cmd, i); },
                     "is a bottom-level build of {} triangles in all geometries (the sum of "
                     "ppBuildRangeInfos[{}][j].primitiveCount), more than "
                     "VkPhysicalDeviceAccelerationStructurePropertiesKHR::maxPrimitiveCount ({}).",
                     total, i, limit);
}

namespace {

// Whether ValidateInfoStructure certainly has nothing to report or count for pInfos[i]: every per-info rule above
// holds (a known type, no exclusive flag pair, one geometry array, a geometry count within the limit the type sets,
// the limit known) and the geometry pass found nothing for this family. Only compares, so that a loop over clean
// infos needs no call and no stack frame; any other info takes the rules, which report exactly as before.
inline bool InfoStructureClean(const CheckContext& ctx, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                               const ResolvedInfo& r) {
  constexpr VkBuildAccelerationStructureFlagsKHR kFastBoth =
      VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  constexpr VkBuildAccelerationStructureFlagsKHR kMicromapBoth =
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT |
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_DATA_UPDATE_EXT;
  if ((r.walks & kWalkStructure) || (info.flags & kFastBoth) == kFastBoth ||
      (info.flags & kMicromapBoth) == kMicromapBoth) {
    return false;
  }
  if (info.geometryCount != 0 && (info.pGeometries == nullptr) == (info.ppGeometries == nullptr)) return false;
  switch (info.type) {
    case VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR:
      return info.geometryCount == 1;
    case VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR: {
      const uint64_t limit = ctx.state.properties.acceleration_structure.maxGeometryCount;
      return limit != 0 && info.geometryCount <= limit;
    }
    case VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR:
      return false;
    default:
      return true;
  }
}

// The rules from pInfos[first] on, the first info that is not certainly clean (out of line).
[[gnu::noinline]] bool ValidateInfosFrom(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved,
                                         uint32_t first) {
  bool skip = false;
  for (uint32_t i = first; i < cmd.info_count; ++i) {
    const ResolvedInfo& r = resolved.info(i);
    if (!InfoStructureClean(ctx, cmd.infos[i], r)) skip |= ValidateInfoStructure(ctx, cmd, i, r);
  }
  return skip;
}

}  // namespace

bool ValidateBuildStructure(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  if (!cmd.infos) return false;
  // The clean infos first, by compares only (no call, no stack frame); the rules from the first other one on.
  uint32_t i = 0;
  while (i < cmd.info_count && InfoStructureClean(ctx, cmd.infos[i], resolved.info(i))) ++i;
  return i < cmd.info_count && ValidateInfosFrom(ctx, cmd, resolved, i);
}

}  // namespace asval
