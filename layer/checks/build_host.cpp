#include "build_host.h"

#include <vector>

#include "build_report.h"
#include "build_sizes.h"
#include "history_recorder.h"
#include "host_instances.h"
#include "host_memory.h"

namespace asval {

namespace {

// The rules a structure's memory must meet in a host build, by the role the structure plays.
struct StructureRole {
  const char* host_visible_rule;
  const char* multi_instance_rule;
};
constexpr StructureRole kDestination = {"pInfos-03722", "pInfos-03775"};
constexpr StructureRole kSource = {"pInfos-03723", "pInfos-03776"};
constexpr StructureRole kReferenced = {"pInfos-03724", "pInfos-03777"};

// How a finding about a structure names it: a member of pInfos[i], or an instance of geometry j.
struct StructurePlace {
  uint32_t info;
  const char* member;  // "dstAccelerationStructure", "srcAccelerationStructure", or null for an instance
  uint32_t geometry;
};

Location PlaceLocation(const BuildCommand& cmd, const StructurePlace& place) {
  if (place.member) return InfoLocation(cmd, place.info).Field(place.member);
  return GeometryLocation(cmd, place.info, place.geometry).Field("geometry").Field("instances").Field("data").Field(
      "hostAddress");
}

// "(instance k) references " for an instance's structure: the first instance that does (found when reporting).
std::string PlacePrefix(const DeviceState& state, const BuildCommand& cmd, const StructurePlace& place,
                        VkAccelerationStructureKHR handle) {
  if (place.member) return "";
  const uint32_t k = FirstInstanceReferencing(state, cmd, place.info, place.geometry, reinterpret_cast<uint64_t>(handle));
  return fmt::format("(instance {}) references ", k);
}

[[gnu::cold, gnu::noinline]] bool ReportStructureMemory(const CheckContext& ctx, const BuildCommand& cmd,
                                                        const StructurePlace& place, const char* rule,
                                                        const StructureHostMemory& host_memory,
                                                        bool host_visible_rule) {
  return ReportBuild(ctx, cmd, place.info, rule, [&](std::string&) { return PlaceLocation(cmd, place); }, "{}{}",
                     PlacePrefix(ctx.state, cmd, place, host_memory.memory.structure->handle),
                     DescribeHostMemoryProblem(host_memory, host_visible_rule));
}

bool ValidateStructureMemory(const CheckContext& ctx, const BuildCommand& cmd, VkAccelerationStructureKHR handle,
                             const StructurePlace& place, const StructureRole& role) {
  const std::optional<StructureHostMemory> host_memory = HostMemoryOfStructure(ctx, handle);
  if (!host_memory) return false;  // unknown: counted
  bool skip = false;
  if (!host_memory->host_visible()) {
    skip |= ReportStructureMemory(ctx, cmd, place, role.host_visible_rule, *host_memory, true);
  }
  if (host_memory->multi_instance()) {
    skip |= ReportStructureMemory(ctx, cmd, place, role.multi_instance_rule, *host_memory, false);
  }
  return skip;
}

[[gnu::cold, gnu::noinline]] bool ReportNullScratch(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                    bool update, VkDeviceSize needed) {
  return ReportBuild(ctx, cmd, i, update ? "pInfos-03726" : "pInfos-03725",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("scratchData").Field("hostAddress"); },
                     "is NULL, but this {} needs {} bytes of scratch ({} reported by "
                     "vkGetAccelerationStructureBuildSizesKHR for this geometry and these counts).",
                     update ? "update" : "build", needed, update ? "updateScratchSize" : "buildScratchSize");
}

[[gnu::cold, gnu::noinline]] bool ReportScratchPastMapping(const CheckContext& ctx, const BuildCommand& cmd,
                                                           uint32_t i, bool update, VkDeviceSize needed,
                                                           uintptr_t begin, uintptr_t end) {
  const std::optional<HostMapping> mapping = ctx.state.host_mappings.Containing(begin);
  return ReportBuild(ctx, cmd, i, update ? "pInfos-03726" : "pInfos-03725",
                     [&](std::string&) { return InfoLocation(cmd, i).Field("scratchData").Field("hostAddress"); },
                     "(0x{:x}) points into the mapping of VkDeviceMemory 0x{:x} (host range [0x{:x}, 0x{:x}){}), but "
                     "this {} needs {} bytes of scratch ({}), {} bytes more than the mapped memory holds from there.",
                     begin, reinterpret_cast<uint64_t>(mapping ? mapping->memory : VK_NULL_HANDLE),
                     mapping ? mapping->begin : begin, end,
                     mapping && mapping->end != end ? ", with the mappings that follow it" : "",
                     update ? "update" : "build", needed, update ? "updateScratchSize" : "buildScratchSize",
                     needed - (end - begin));
}

bool ValidateHostScratch(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, const ResolvedInfo& r) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  // The resolved sizes when the memory families had them looked up; else asked here.
  const std::optional<BuildSizes> sizes = r.placed ? r.sizes : SizesOfInfo(ctx.state, cmd, i);
  if (!sizes) {
    CountUnknownState(ctx);
    return false;  // without the size, a null pointer may be all a zero-size scratch needs
  }
  const bool update = info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  const VkDeviceSize needed = update ? sizes->update_scratch_size : sizes->build_scratch_size;
  if (needed == 0) return false;
  if (info.scratchData.hostAddress == nullptr) return ReportNullScratch(ctx, cmd, i, update, needed);
  // Where the pointer lies in memory the app mapped, the scratch must fit in the mapping (or mappings that
  // continue it); elsewhere the layer cannot know how much memory is behind the pointer.
  const auto begin = reinterpret_cast<uintptr_t>(info.scratchData.hostAddress);
  const uintptr_t end = ctx.state.host_mappings.ContiguousEnd(begin);
  if (end == 0 || needed <= end - begin) return false;
  return ReportScratchPastMapping(ctx, cmd, i, update, needed, begin, end);
}

[[gnu::cold, gnu::noinline]] bool ReportNullInput(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                                                  uint32_t j, const char* rule, const char* data_member,
                                                  const char* field, uint32_t count) {
  return ReportBuild(ctx, cmd, i, rule,
                     [&](std::string&) {
                       return GeometryLocation(cmd, i, j).Field("geometry").Field(data_member).Field(field).Field(
                           "hostAddress");
                     },
                     "is NULL, but ppBuildRangeInfos[{}][{}].primitiveCount is {}: it must be a valid host address.",
                     i, j, count);
}

bool ValidateInstanceReferences(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i, uint32_t j,
                                std::vector<uint64_t>& references) {
  references.clear();
  if (!CollectInstanceReferences(ctx.state, cmd, i, j, references)) return false;
  bool skip = false;
  const StructurePlace place{i, nullptr, j};
  for (uint64_t reference : references) {
    const auto handle = reinterpret_cast<VkAccelerationStructureKHR>(reference);
    if (ctx.state.acceleration_structures.contains(handle)) {
      skip |= ValidateStructureMemory(ctx, cmd, handle, place, kReferenced);
      continue;
    }
    skip |= ReportBuild(ctx, cmd, i, "pInfos-03779", [&](std::string&) { return PlaceLocation(cmd, place); },
                        "(instance {}) has accelerationStructureReference 0x{:x}, which is not a live "
                        "VkAccelerationStructureKHR of this device.",
                        FirstInstanceReferencing(ctx.state, cmd, i, j, reference), reference);
  }
  return skip;
}

bool ValidateHostInputs(const CheckContext& ctx, const BuildCommand& cmd, uint32_t i,
                        std::vector<uint64_t>& references) {
  const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
  // Past maxGeometryCount the arrays may be shorter than the count (type-03793 covers the info).
  if (!cmd.ranges || !cmd.ranges[i] || !GeometriesWalkable(ctx, info)) return false;
  bool skip = false;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkAccelerationStructureGeometryKHR* g = GeometryAt(info, j);
    if (!g) return skip;
    const uint32_t count = cmd.ranges[i][j].primitiveCount;
    if (count == 0) continue;  // builds nothing, reads nothing
    switch (g->geometryType) {
      case VK_GEOMETRY_TYPE_TRIANGLES_KHR: {
        const VkAccelerationStructureGeometryTrianglesDataKHR& t = g->geometry.triangles;
        if (!t.vertexData.hostAddress) {
          skip |= ReportNullInput(ctx, cmd, i, j, "pInfos-03771", "triangles", "vertexData", count);
        }
        if (t.indexType != VK_INDEX_TYPE_NONE_KHR && !t.indexData.hostAddress) {
          skip |= ReportNullInput(ctx, cmd, i, j, "pInfos-03772", "triangles", "indexData", count);
        }
        break;
      }
      case VK_GEOMETRY_TYPE_AABBS_KHR:
        if (!g->geometry.aabbs.data.hostAddress) {
          skip |= ReportNullInput(ctx, cmd, i, j, "pInfos-03774", "aabbs", "data", count);
        }
        break;
      case VK_GEOMETRY_TYPE_INSTANCES_KHR:
        if (!g->geometry.instances.data.hostAddress) {
          skip |= ReportNullInput(ctx, cmd, i, j, "pInfos-03778", "instances", "data", count);
        } else {
          skip |= ValidateInstanceReferences(ctx, cmd, i, j, references);
        }
        break;
      default:
        break;
    }
  }
  return skip;
}

// deferredOperation-03678. The layer knows an operation is still running when one of its host builds or
// copies returned VK_OPERATION_DEFERRED_KHR and no join, result query or destroy has seen it complete since
// (tracked by the history records while the history or copies family is on; else nothing is known).
bool ValidateDeferredOperation(const CheckContext& ctx, const BuildCommand& cmd) {
  if (cmd.deferred_operation == VK_NULL_HANDLE) return false;
  // HasDeferredOps only reads, under the history's own mutex; DeviceData owns the state as non-const.
  if (!HasDeferredOps(ctx.state, cmd.deferred_operation)) return false;
  return ReportBuild(ctx, cmd, kNoInfo, "deferredOperation-03678",
                     [&](std::string&) { return cmd.Root().Field("deferredOperation"); },
                     "(VkDeferredOperationKHR 0x{:x}) is still associated with an earlier host command that returned "
                     "VK_OPERATION_DEFERRED_KHR and has not been seen to complete (vkDeferredOperationJoinKHR "
                     "returning VK_SUCCESS, or vkGetDeferredOperationResultKHR returning other than VK_NOT_READY).",
                     reinterpret_cast<uint64_t>(cmd.deferred_operation));
}

}  // namespace

bool ValidateBuildHost(const CheckContext& ctx, const BuildCommand& cmd, const ResolvedBuild& resolved) {
  if (!cmd.is_host() || !cmd.infos) return false;
  std::vector<uint64_t> references;  // instance references of one geometry (host builds are not a hot path)
  bool skip = ValidateDeferredOperation(ctx, cmd);
  for (uint32_t i = 0; i < cmd.info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = cmd.infos[i];
    skip |= ValidateStructureMemory(ctx, cmd, info.dstAccelerationStructure,
                                    StructurePlace{i, "dstAccelerationStructure", 0}, kDestination);
    if (info.mode == VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR &&
        info.srcAccelerationStructure != VK_NULL_HANDLE) {
      skip |= ValidateStructureMemory(ctx, cmd, info.srcAccelerationStructure,
                                      StructurePlace{i, "srcAccelerationStructure", 0}, kSource);
    }
    skip |= ValidateHostScratch(ctx, cmd, i, resolved.info(i));
    skip |= ValidateHostInputs(ctx, cmd, i, references);
  }
  return skip;
}

}  // namespace asval
