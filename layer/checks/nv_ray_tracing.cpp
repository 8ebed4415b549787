#include "nv_ray_tracing.h"

#include <fmt/format.h>

#include <memory>
#include <optional>

#include "build_report.h"
#include "memory_range.h"
#include "nv_structures.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

constexpr const char kBuild[] = "vkCmdBuildAccelerationStructureNV";
constexpr const char kCopy[] = "vkCmdCopyAccelerationStructureNV";
constexpr const char kWrite[] = "vkCmdWriteAccelerationStructuresPropertiesNV";

template <typename... Args>
[[gnu::cold, gnu::noinline]] bool Report(const CheckContext& ctx, VkCommandBuffer cb, VkAccelerationStructureNV as,
                                         const char* function, const char* suffix, const Location& loc,
                                         fmt::format_string<Args...> format, Args&&... args) {
  return ctx.reporter.Report(
      Severity::kError, std::string("VUID-") + function + "-" + suffix, loc,
      {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, cb), Obj(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_NV, as)},
      fmt::format(format, std::forward<Args>(args)...));
}

std::shared_ptr<const NvStructureState> Find(const CheckContext& ctx, VkAccelerationStructureNV handle) {
  if (handle == VK_NULL_HANDLE) return nullptr;
  std::optional<std::shared_ptr<const NvStructureState>> found = ctx.state.nv_structures.find(handle);
  return found ? std::move(*found) : nullptr;
}

// "bound completely and contiguously to a single VkDeviceMemory object via vkBindAccelerationStructureMemoryNV"
// (dst-07787, dst-07792, accelerationStructure-03757): one bind info binds the whole structure, so bound is enough.
bool CheckBound(const CheckContext& ctx, VkCommandBuffer cb, const NvStructureState* structure,
                VkAccelerationStructureNV handle, const char* function, const char* suffix, const Location& loc) {
  if (!structure) {
    CountUnknownState(ctx);  // a structure the layer does not know
    return false;
  }
  if (structure->bound) return false;
  return Report(ctx, cb, handle, function, suffix, loc,
                "(VkAccelerationStructureNV {}) is not bound to memory: vkBindAccelerationStructureMemoryNV has not "
                "bound it.",
                Hex(handle));
}

// ---- vkCmdBuildAccelerationStructureNV ----

// dst-02488: dst's creation info has the build's type and flags, and room for its instances, geometries and each
// geometry's vertices, indices and AABBs.
bool CheckDstHoldsBuild(const CheckContext& ctx, VkCommandBuffer cb, const NvBuildArgs& a,
                        const NvStructureState& dst) {
  const VkAccelerationStructureInfoNV& info = *a.info;
  const Location root = Location(kBuild).Field("pInfo");
  bool skip = false;
  const auto report = [&](const Location& loc, const std::string& what) {
    return Report(ctx, cb, a.dst, kBuild, "dst-02488", loc,
                  "{}: dst {} was not created with a compatible "
                  "VkAccelerationStructureInfoNV.",
                  what, Hex(a.dst));
  };
  if (info.type != dst.type) {
    skip |= report(root.Field("type"), fmt::format("is {}, but dst was created with type {}",
                                                   string_VkAccelerationStructureTypeKHR(info.type),
                                                   string_VkAccelerationStructureTypeKHR(dst.type)));
  }
  if (info.flags != dst.flags) {
    skip |= report(root.Field("flags"),
                   fmt::format("is 0x{:x}, but dst was created with flags 0x{:x}", info.flags, dst.flags));
  }
  if (info.instanceCount > dst.instance_count) {
    skip |= report(root.Field("instanceCount"), fmt::format("is {}, more than the instanceCount {} dst was created "
                                                            "with",
                                                            info.instanceCount, dst.instance_count));
  }
  if (info.geometryCount > dst.geometries.size()) {
    return skip |
           report(root.Field("geometryCount"), fmt::format("is {}, more than the geometryCount {} dst was created with",
                                                           info.geometryCount, dst.geometries.size()));
  }
  if (!info.pGeometries) return skip;
  for (uint32_t j = 0; j < info.geometryCount; ++j) {
    const VkGeometryNV& g = info.pGeometries[j];
    const NvStructureState::GeometryRoom& room = dst.geometries[j];
    const Location at = root.Field("pGeometries", j);
    if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_NV) {
      const VkGeometryTrianglesNV& t = g.geometry.triangles;
      const uint32_t indices = t.indexType == VK_INDEX_TYPE_NONE_NV ? 0 : t.indexCount;
      if (t.vertexCount > room.vertices) {
        skip |= report(at.Field("geometry").Field("triangles").Field("vertexCount"),
                       fmt::format("is {}, more than the {} vertices geometry {} of dst was created with",
                                   t.vertexCount, room.vertices, j));
      }
      if (indices > room.indices) {
        skip |= report(at.Field("geometry").Field("triangles").Field("indexCount"),
                       fmt::format("is {}, more than the {} indices geometry {} of dst was created with", indices,
                                   room.indices, j));
      }
    } else if (g.geometryType == VK_GEOMETRY_TYPE_AABBS_NV && g.geometry.aabbs.numAABBs > room.aabbs) {
      skip |= report(at.Field("geometry").Field("aabbs").Field("numAABBs"),
                     fmt::format("is {}, more than the {} AABBs geometry {} of dst was created with",
                                 g.geometry.aabbs.numAABBs, room.aabbs, j));
    }
  }
  return skip;
}

// update-02491 / update-02492: scratch minus scratchOffset holds the memory requirement of dst's build or update.
bool CheckScratchSize(const CheckContext& ctx, VkCommandBuffer cb, const NvBuildArgs& a, const NvStructureState& dst,
                      const BufferState& scratch) {
  const bool update = a.update == VK_TRUE;
  const VkDeviceSize needed = update ? dst.update_scratch_size : dst.build_scratch_size;
  if (needed == 0) {
    CountUnknownState(ctx);  // the requirement could not be asked
    return false;
  }
  const VkDeviceSize room = a.scratch_offset <= scratch.size ? scratch.size - a.scratch_offset : 0;
  if (room >= needed) return false;
  return Report(ctx, cb, a.dst, kBuild, update ? "update-02492" : "update-02491", Location(kBuild).Field("scratch"),
                "(VkBuffer {}) has {} bytes from scratchOffset {} on, less than the {} bytes "
                "vkGetAccelerationStructureMemoryRequirementsNV asks for dst {} ({}).",
                Hex(a.scratch), room, a.scratch_offset, needed, Hex(a.dst),
                update ? "VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV"
                       : "VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV");
}

bool CheckRayTracingUsage(const CheckContext& ctx, VkCommandBuffer cb, VkAccelerationStructureNV dst, VkBuffer buffer,
                          const BufferState* state, const char* suffix, const char* field) {
  if (!state) {
    CountUnknownState(ctx);
    return false;
  }
  if (state->usage & VK_BUFFER_USAGE_RAY_TRACING_BIT_NV) return false;
  return Report(ctx, cb, dst, kBuild, suffix, Location(kBuild).Field(field),
                "(VkBuffer {}) was created with usage 0x{:x}, without VK_BUFFER_USAGE_RAY_TRACING_BIT_NV.", Hex(buffer),
                state->usage);
}

std::shared_ptr<const BufferState> FindBuffer(const CheckContext& ctx, VkBuffer buffer) {
  std::optional<std::shared_ptr<const BufferState>> found = ctx.state.buffers.find(buffer);
  return found ? std::move(*found) : nullptr;
}

// update-03526: an update's src and dst are the same object or share no memory.
bool CheckUpdateAliasing(const CheckContext& ctx, VkCommandBuffer cb, const NvBuildArgs& a,
                         const NvStructureState* dst) {
  if (a.update != VK_TRUE || !a.src || a.src == a.dst) return false;
  const std::shared_ptr<const NvStructureState> src = Find(ctx, a.src);
  const std::optional<MemorySpan> src_span = src ? NvStructureSpan(*src) : std::nullopt;
  const std::optional<MemorySpan> dst_span = dst ? NvStructureSpan(*dst) : std::nullopt;
  if (!src_span || !dst_span) {
    CountUnknownState(ctx);
    return false;
  }
  if (!Overlaps(*src_span, *dst_span)) return false;
  return Report(ctx, cb, a.dst, kBuild, "update-03526", Location(kBuild).Field("dst"),
                "(VkAccelerationStructureNV {}) occupies bytes [{}, {}) of VkDeviceMemory {}, which overlap the bytes "
                "[{}, {}) that src (VkAccelerationStructureNV {}) occupies; an update's src and dst must be the same "
                "object or not alias.",
                Hex(a.dst), dst_span->begin, dst_span->end, Hex(dst_span->memory), src_span->begin, src_span->end,
                Hex(a.src));
}

}  // namespace

bool ValidateBuildNV(const CheckContext& ctx, VkCommandBuffer cb, const NvBuildArgs& a) {
  if (!a.info) return false;  // the Khronos layer's (pInfo-parameter)
  const Location root(kBuild);
  bool skip = false;
  const std::shared_ptr<const NvStructureState> dst = Find(ctx, a.dst);
  if (ctx.Enabled(kCheckStructure)) {
    const uint32_t max = ctx.state.properties.ray_tracing_nv.maxGeometryCount;
    if (max == 0) {
      CountUnknownState(ctx);
    } else if (a.info->geometryCount > max) {
      skip |= Report(ctx, cb, a.dst, kBuild, "geometryCount-02241", root.Field("pInfo").Field("geometryCount"),
                     "({}) is more than VkPhysicalDeviceRayTracingPropertiesNV::maxGeometryCount ({}).",
                     a.info->geometryCount, max);
    }
    if (!dst) {
      CountUnknownState(ctx);
    } else {
      skip |= CheckDstHoldsBuild(ctx, cb, a, *dst);
    }
  }
  if (ctx.Enabled(kCheckHandles)) {
    if (a.update == VK_TRUE && a.src == VK_NULL_HANDLE) {
      skip |= Report(ctx, cb, a.dst, kBuild, "update-02489", root.Field("src"),
                     "is VK_NULL_HANDLE, but update is VK_TRUE: an update needs the structure it updates from.");
    }
    skip |= CheckBound(ctx, cb, dst.get(), a.dst, kBuild, "dst-07787", root.Field("dst"));
  }
  if (ctx.Enabled(kCheckAddresses)) {
    const std::shared_ptr<const BufferState> scratch = FindBuffer(ctx, a.scratch);
    skip |= CheckRayTracingUsage(ctx, cb, a.dst, a.scratch, scratch.get(), "scratch-03522", "scratch");
    if (a.instance_data != VK_NULL_HANDLE) {
      const std::shared_ptr<const BufferState> instances = FindBuffer(ctx, a.instance_data);
      skip |=
          CheckRayTracingUsage(ctx, cb, a.dst, a.instance_data, instances.get(), "instanceData-03523", "instanceData");
    }
    if (!dst || !scratch) {
      CountUnknownState(ctx);
    } else {
      skip |= CheckScratchSize(ctx, cb, a, *dst, *scratch);
    }
  }
  if (ctx.Enabled(kCheckAliasing)) skip |= CheckUpdateAliasing(ctx, cb, a, dst.get());
  return skip;
}

bool ValidateCopyNV(const CheckContext& ctx, VkCommandBuffer cb, VkAccelerationStructureNV dst,
                    VkAccelerationStructureNV src, VkCopyAccelerationStructureModeKHR mode) {
  const Location root(kCopy);
  bool skip = false;
  if (mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR &&
      mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR) {
    skip |= Report(ctx, cb, src, kCopy, "mode-03410", root.Field("mode"),
                   "is {}; a copy between structures must be VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR or "
                   "VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR.",
                   string_VkCopyAccelerationStructureModeKHR(mode));
  }
  const std::shared_ptr<const NvStructureState> dst_state = Find(ctx, dst);
  skip |= CheckBound(ctx, cb, dst_state.get(), dst, kCopy, "dst-07792", root.Field("dst"));
  const std::shared_ptr<const NvStructureState> src_state = Find(ctx, src);
  const std::optional<MemorySpan> src_span = src_state ? NvStructureSpan(*src_state) : std::nullopt;
  const std::optional<MemorySpan> dst_span = dst_state ? NvStructureSpan(*dst_state) : std::nullopt;
  if (!src_span || !dst_span) {
    CountUnknownState(ctx);
  } else if (Overlaps(*src_span, *dst_span)) {
    skip |= Report(ctx, cb, dst, kCopy, "dst-07791", root.Field("dst"),
                   "(VkAccelerationStructureNV {}) occupies bytes [{}, {}) of VkDeviceMemory {}, which overlap the "
                   "bytes [{}, {}) that src (VkAccelerationStructureNV {}) occupies.",
                   Hex(dst), dst_span->begin, dst_span->end, Hex(dst_span->memory), src_span->begin, src_span->end,
                   Hex(src));
  }
  return skip;
}

bool ValidateWritePropertiesNV(const CheckContext& ctx, VkCommandBuffer cb, uint32_t count,
                               const VkAccelerationStructureNV* structures, VkQueryType type, VkQueryPool pool) {
  const Location root(kWrite);
  bool skip = false;
  if (type != VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV) {
    skip |=
        Report(ctx, cb, VK_NULL_HANDLE, kWrite, "queryType-06216", root.Field("queryType"),
               "is {}; it must be VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV.", string_VkQueryType(type));
  }
  if (std::optional<QueryPoolState> pool_state = ctx.state.history.query_pools.find(pool)) {
    if (pool_state->type != type) {
      skip |= Report(ctx, cb, VK_NULL_HANDLE, kWrite, "queryPool-03755", root.Field("queryPool"),
                     "(VkQueryPool {}) was created with queryType {}, not the queryType {} of this command.", Hex(pool),
                     string_VkQueryType(pool_state->type), string_VkQueryType(type));
    }
  } else {
    CountUnknownState(ctx);
  }
  for (uint32_t i = 0; structures && i < count; ++i) {
    const std::shared_ptr<const NvStructureState> s = Find(ctx, structures[i]);
    skip |= CheckBound(ctx, cb, s.get(), structures[i], kWrite, "accelerationStructure-03757",
                       root.Field("pAccelerationStructures", i));
  }
  return skip;
}

}  // namespace asval
