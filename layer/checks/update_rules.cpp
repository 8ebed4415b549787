#include "update_rules.h"

#include <fmt/format.h>

#include "build_report.h"
#include "layer_settings.h"
#include "nv_structures.h"
#include "recorded_objects.h"
#include "traced_structures.h"
#include "vk_enum_string.h"

namespace asval {

namespace {

std::string BuildFlagsText(VkBuildAccelerationStructureFlagsKHR flags) {
  char buf[512];
  return fmt::format("{} (0x{:x})", string_VkBuildAccelerationStructureFlagsKHR(flags, buf, sizeof(buf)), flags);
}

std::string GeometryFlagsText(VkGeometryFlagsKHR flags) {
  char buf[256];
  return fmt::format("{} (0x{:x})", string_VkGeometryFlagsKHR(flags, buf, sizeof(buf)), flags);
}

// Everything a check needs to word and file one finding about `op`.
struct OpReporter {
  const DeviceState& state;
  const HistoryStore& store;
  const OpBatch& batch;
  const AsOp& op;
  const HistoryCheckSite& site;
  HistoryFindings& out;

  // "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"
  std::string CommandVuid(const char* suffix) const {
    return std::string("VUID-") + OpCommandName(op.origin.command) + "-" + suffix;
  }
  // VK_NV_ray_tracing's commands name VkAccelerationStructureNV handles (their history keys: nv_structures.h).
  bool nv() const { return IsNvCommand(op.origin.command); }
  const char* TypeName() const { return nv() ? "VkAccelerationStructureNV" : "VkAccelerationStructureKHR"; }
  // Host calls: the element's own location; at submission the submitted command buffer's.
  Location Where() const {
    if (site.describe_origin) return site.loc;
    const std::string_view array = OpCommandArrayName(op.origin.command);
    if (array.empty()) return site.loc;
    if (array == "pInfo") return site.loc.Field("pInfo");
    return site.loc.Field(OpCommandArrayName(op.origin.command), op.origin.element);
  }
  std::string Prefix() const { return site.describe_origin ? DescribeOrigin(op.origin) + ": " : std::string(); }

  [[gnu::cold, gnu::noinline]] void Add(Severity severity, std::string vuid, VkAccelerationStructureKHR subject,
                                        std::string message) const {
    const VkObjectType type =
        nv() ? VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_NV : VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR;
    out.Add(severity, std::move(vuid), Where(),
            {Obj(VK_OBJECT_TYPE_COMMAND_BUFFER, site.submitted), Obj(type, subject),
             Obj(type, op.dst == subject ? VK_NULL_HANDLE : op.dst)},
            Prefix() + message);
  }

  void CountSkip() const {
    state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
    store.rules_skipped_unknown_history.fetch_add(1, std::memory_order_relaxed);
  }
};

// The history of a structure an operation reads, or nothing (skip counted) when it cannot be judged: a handle
// the layer does not know as a live structure (another family's rule), or an unknown history. A structure
// with a record is live (records end when structures are destroyed), so only one without needs the lookup.
const AsHistory* ReadableHistory(const OpReporter& r, VkAccelerationStructureKHR as, AsHistory* storage) {
  const AsHistory* h = r.store.Find(as);
  if (!h) {
    if (!r.state.acceleration_structures.contains(as) && !FindNvByKey(r.state, as)) {
      r.CountSkip();
      return nullptr;
    }
    *storage = r.store.Get(as);  // live, without a record: never built
    h = storage;
  }
  if (h->kind == HistoryKind::kUnknown) {
    r.CountSkip();
    return nullptr;
  }
  return h;
}

[[gnu::cold, gnu::noinline]] void ReportClobbered(const OpReporter& r, VkAccelerationStructureKHR as,
                                                  const AsHistory& h, const char* use) {
  const Clobber& c = *h.clobbered;
  const char* writer_type = IsNvCommand(c.by.command) ? "VkAccelerationStructureNV" : "VkAccelerationStructureKHR";
  const std::string writer = c.writer ? fmt::format("writing {} {}", writer_type, Hex(c.writer))
                                      : std::string("writing serialized data");
  r.Add(Severity::kWarning, kClobberedId, as,
        fmt::format("{} {} {} after its memory was overwritten: {} ({}) wrote memory that overlaps it after it was "
                    "last built. Its contents are no longer what was built; rebuild it before using it.",
                    use, r.TypeName(), Hex(as), DescribeOrigin(c.by), writer));
}

// ---- updates -------------------------------------------------------------------------------------------------

[[gnu::cold, gnu::noinline]] void ReportNeverBuiltSource(const OpReporter& r) {
  r.Add(Severity::kError, r.CommandVuid("pInfos-03667"), r.op.src,
        fmt::format("is an update (mode VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR) of srcAccelerationStructure "
                    "{}, which has not been built by any operation executed before it.",
                    Hex(r.op.src)));
}

std::string LastBuilt(const OpReporter& r, const BuildSnapshot& s) {
  return fmt::format("{} {} was last built by {}", r.nv() ? "src" : "srcAccelerationStructure", Hex(r.op.src),
                     DescribeOrigin(s.origin));
}

[[gnu::cold, gnu::noinline]] void CompareUpdate(const OpReporter& r, const BuildSnapshot& s) {
  const AsOp& op = r.op;
  if (!(s.flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR)) {
    r.Add(Severity::kError, r.CommandVuid("pInfos-03667"), op.src,
          fmt::format("is an update, but {} with flags {}, without "
                      "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR.",
                      LastBuilt(r, s), BuildFlagsText(s.flags)));
  }
  if (s.geometries.size() != op.geometry_count) {
    r.Add(Severity::kError, r.CommandVuid("pInfos-03758"), op.src,
          fmt::format("geometryCount is {}, but {} with geometryCount {}.", op.geometry_count, LastBuilt(r, s),
                      s.geometries.size()));
  }
  if (s.flags != op.flags) {
    r.Add(Severity::kError, r.CommandVuid("pInfos-03759"), op.src,
          fmt::format("flags is {}, but {} with flags {}.", BuildFlagsText(op.flags), LastBuilt(r, s),
                      BuildFlagsText(s.flags)));
  }
  if (s.type != op.type) {
    r.Add(Severity::kError, r.CommandVuid("pInfos-03760"), op.src,
          fmt::format("type is {}, but {} with type {}.", string_VkAccelerationStructureTypeKHR(op.type),
                      LastBuilt(r, s), string_VkAccelerationStructureTypeKHR(s.type)));
  }
  const GeometryRecord* now = r.batch.GeometriesOf(op);
  const uint32_t common = std::min<uint32_t>(op.geometry_count, static_cast<uint32_t>(s.geometries.size()));
  for (uint32_t j = 0; j < common; ++j) {
    const GeometryRecord& g = now[j];
    const GeometryRecord& b = s.geometries[j];
    const std::string at = fmt::format("geometry {}: ", j);
    if (g.type != b.type) {
      r.Add(Severity::kError, r.CommandVuid("pInfos-03761"), op.src,
            fmt::format("{}geometryType is {}, but {} with {}.", at, string_VkGeometryTypeKHR(g.type), LastBuilt(r, s),
                        string_VkGeometryTypeKHR(b.type)));
      continue;  // the per-type members below compare different things
    }
    if (g.flags != b.flags) {
      r.Add(Severity::kError, r.CommandVuid("pInfos-03762"), op.src,
            fmt::format("{}flags is {}, but {} with {}.", at, GeometryFlagsText(g.flags), LastBuilt(r, s),
                        GeometryFlagsText(b.flags)));
    }
    if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
      if (g.vertex_format != b.vertex_format) {
        r.Add(Severity::kError, r.CommandVuid("pInfos-03763"), op.src,
              fmt::format("{}geometry.triangles.vertexFormat is {}, but {} with {}.", at,
                          string_VkFormat(g.vertex_format), LastBuilt(r, s), string_VkFormat(b.vertex_format)));
      }
      if (g.max_vertex != b.max_vertex) {
        r.Add(Severity::kError, r.CommandVuid("pInfos-03764"), op.src,
              fmt::format("{}geometry.triangles.maxVertex is {}, but {} with {}.", at, g.max_vertex, LastBuilt(r, s),
                          b.max_vertex));
      }
      if (g.index_type != b.index_type) {
        r.Add(Severity::kError, r.CommandVuid("pInfos-03765"), op.src,
              fmt::format("{}geometry.triangles.indexType is {}, but {} with {}.", at, string_VkIndexType(g.index_type),
                          LastBuilt(r, s), string_VkIndexType(b.index_type)));
      }
      if (!b.has_transform && g.has_transform) {
        r.Add(Severity::kError, r.CommandVuid("pInfos-03766"), op.src,
              fmt::format("{}geometry.triangles.transformData is not NULL, but {} with a NULL transformData.", at,
                          LastBuilt(r, s)));
      }
      if (b.has_transform && !g.has_transform) {
        r.Add(Severity::kError, r.CommandVuid("pInfos-03767"), op.src,
              fmt::format("{}geometry.triangles.transformData is NULL, but {} with a non-NULL transformData.", at,
                          LastBuilt(r, s)));
      }
    }
    if (!g.primitive_count_known || !b.primitive_count_known) {
      if (!op.counts_captured()) r.CountSkip();  // an indirect build's count lives on the device
    } else if (g.primitive_count != b.primitive_count) {
      r.Add(Severity::kError, r.CommandVuid("primitiveCount-03769"), op.src,
            fmt::format("{}the build range's primitiveCount is {}, but {} with primitiveCount {}.", at,
                        g.primitive_count, LastBuilt(r, s), b.primitive_count));
    }
  }
}

// The clean path: an update that repeats its source's last build compares equal and formats nothing.
// *unknown_counts: geometries whose primitive count one side does not know (an indirect build's count lives
// on the device); counted as skips by the caller, once (CompareUpdate counts them itself), unless the update's
// counts are captured: the comparison is then made, or counted, when the update completes (indirect_rules.h).
bool UpdateMatches(const OpReporter& r, const BuildSnapshot& s, uint32_t* unknown_counts) {
  const AsOp& op = r.op;
  if (!(s.flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR) || s.flags != op.flags || s.type != op.type ||
      s.geometries.size() != op.geometry_count) {
    return false;
  }
  const GeometryRecord* now = r.batch.GeometriesOf(op);
  for (uint32_t j = 0; j < op.geometry_count; ++j) {
    const GeometryRecord& g = now[j];
    const GeometryRecord& b = s.geometries[j];
    if (g.type != b.type || g.flags != b.flags) return false;
    if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR &&
        (g.vertex_format != b.vertex_format || g.max_vertex != b.max_vertex || g.index_type != b.index_type ||
         g.has_transform != b.has_transform)) {
      return false;
    }
    if (!g.primitive_count_known || !b.primitive_count_known) {
      ++*unknown_counts;
    } else if (g.primitive_count != b.primitive_count) {
      return false;
    }
  }
  return true;
}

// vkCmdBuildAccelerationStructureNV-update-02490: src was built with ALLOW_UPDATE. (Unlike the KHR command, the NV
// one asks nothing else of the source's last build: dst-02488 compares the build with dst's creation info.)
void CheckNvUpdate(const OpReporter& r) {
  AsHistory storage;
  const AsHistory* h = ReadableHistory(r, r.op.src, &storage);
  if (!h) return;
  if (h->clobbered) ReportClobbered(r, r.op.src, *h, "updates from");
  if (h->kind == HistoryKind::kNeverBuilt || !h->build) {
    r.Add(Severity::kError, "VUID-vkCmdBuildAccelerationStructureNV-update-02490", r.op.src,
          fmt::format("update is VK_TRUE, but src {} has not been built by any operation executed before it: it was "
                      "never constructed with VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV.",
                      Hex(r.op.src)));
    return;
  }
  if (!(h->build->flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV)) {
    r.Add(Severity::kError, "VUID-vkCmdBuildAccelerationStructureNV-update-02490", r.op.src,
          fmt::format("update is VK_TRUE, but {} with flags {}, without "
                      "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_NV.",
                      LastBuilt(r, *h->build), BuildFlagsText(h->build->flags)));
  }
}

void CheckUpdate(const OpReporter& r) {
  if (r.nv()) return CheckNvUpdate(r);
  AsHistory storage;
  const AsHistory* h = ReadableHistory(r, r.op.src, &storage);
  if (!h) return;
  if (h->clobbered) ReportClobbered(r, r.op.src, *h, "updates from");
  if (h->kind == HistoryKind::kNeverBuilt || !h->build) {
    ReportNeverBuiltSource(r);
    return;
  }
  if (r.op.geometries_unreadable) {
    r.CountSkip();  // a null geometry pointer: the structure family reports it; nothing to compare
    return;
  }
  uint32_t unknown_counts = 0;
  if (!UpdateMatches(r, *h->build, &unknown_counts)) {
    CompareUpdate(r, *h->build);
    return;
  }
  if (r.op.counts_captured()) return;
  for (uint32_t k = 0; k < unknown_counts; ++k) r.CountSkip();
}

// ---- copies, serialization, property queries -----------------------------------------------------------------

void CheckCopySource(const OpReporter& r) {
  AsHistory storage;
  const AsHistory* h = ReadableHistory(r, r.op.src, &storage);
  if (!h) return;
  const bool to_memory = r.op.kind == OpKind::kSerialize;
  if (h->clobbered) ReportClobbered(r, r.op.src, *h, to_memory ? "serializes" : "copies from");
  if (h->kind == HistoryKind::kNeverBuilt) {
    r.Add(Severity::kError,
          to_memory ? "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-04959"
          : r.nv()  ? "VUID-vkCmdCopyAccelerationStructureNV-src-04963"
                    : "VUID-VkCopyAccelerationStructureInfoKHR-src-04963",
          r.op.src,
          fmt::format("src {} has not been constructed (built, copied or deserialized) by any operation executed "
                      "before this {}.",
                      Hex(r.op.src), to_memory ? "serialization" : "copy"));
    return;
  }
  if (!to_memory && r.op.copy_mode == VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR && h->build &&
      !(h->build->flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR)) {
    r.Add(Severity::kError,
          r.nv() ? "VUID-vkCmdCopyAccelerationStructureNV-src-03411"
                 : "VUID-VkCopyAccelerationStructureInfoKHR-src-03411",
          r.op.src,
          fmt::format("mode is VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR, but src {} was last built by {} "
                      "with flags {}, without VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR.",
                      Hex(r.op.src), DescribeOrigin(h->build->origin), BuildFlagsText(h->build->flags)));
  }
}

// dst-03561: the memory must hold the serialization size the app read back for the source's current contents.
void CheckSerializationRoom(const OpReporter& r) {
  const AsHistory h = r.store.Get(r.op.src);
  const bool size_known = h.serialization_size_generation != 0 && h.serialization_size_generation == h.generation;
  if (!size_known || r.op.memory.capacity == 0) {
    r.CountSkip();  // no size read back for these contents, or memory the layer cannot measure (host pointers)
    return;
  }
  if (r.op.memory.capacity >= h.serialization_size) return;
  r.Add(Severity::kError, "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561", r.op.src,
        fmt::format("dst.deviceAddress 0x{:x} has {} bytes up to the end of the largest buffer containing it, less "
                    "than the serialization size of src {} ({} bytes, as read back from a "
                    "VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR query of its current contents).",
                    r.op.memory.device_address, r.op.memory.capacity, Hex(r.op.src), h.serialization_size));
}

void CheckPropertySource(const OpReporter& r) {
  AsHistory storage;
  const AsHistory* h = ReadableHistory(r, r.op.dst, &storage);
  if (!h) return;
  if (h->kind == HistoryKind::kNeverBuilt) {
    r.Add(Severity::kError, r.CommandVuid(r.nv() ? "pAccelerationStructures-04958" : "pAccelerationStructures-04964"),
          r.op.dst,
          fmt::format("{} {} has not been built by any operation executed before this property query.", r.TypeName(),
                      Hex(r.op.dst)));
    return;
  }
  const VkQueryType compacted = r.nv() ? VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV
                                       : VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
  if (r.op.query_type == compacted && h->build &&
      !(h->build->flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR)) {
    r.Add(Severity::kError,
          r.CommandVuid(r.nv() ? "pAccelerationStructures-06215" : "accelerationStructures-03431"), r.op.dst,
          fmt::format("queryType is {}, but {} {} was last built by {} with flags {}, without "
                      "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR.",
                      string_VkQueryType(r.op.query_type), r.TypeName(), Hex(r.op.dst),
                      DescribeOrigin(h->build->origin), BuildFlagsText(h->build->flags)));
  }
}

}  // namespace

void CheckOpHistory(const DeviceState& state, const HistoryStore& store, uint32_t enabled_checks,
                    const OpBatch& batch, const AsOp& op, const HistoryCheckSite& site, HistoryFindings& out) {
  const OpReporter r{state, store, batch, op, site, out};
  const bool history = (enabled_checks & kCheckHistory) != 0;
  if (enabled_checks & kCheckLifetime) CheckRecordedObjects(state, batch, op, site, out);
  switch (op.kind) {
    case OpKind::kBuild:
      if (history && op.is_update()) CheckUpdate(r);
      break;
    case OpKind::kCopy:
      if (history) CheckCopySource(r);
      break;
    case OpKind::kSerialize:
      if (history) CheckCopySource(r);
      if (enabled_checks & kCheckCopies) CheckSerializationRoom(r);
      break;
    case OpKind::kDeserialize:
      break;  // what it restores is decided when it is applied (history_apply.cpp)
    case OpKind::kWriteProperties:
      if (history) CheckPropertySource(r);
      break;
    case OpKind::kTrace:
      if (enabled_checks & kCheckTraces) CheckTracedStructures(state, store, batch, op, site, out);
      break;
  }
}

}  // namespace asval
