#include "command_buffer_ops.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>

#include "geometry_limit.h"

namespace asval {

const char* OpCommandName(OpCommand command) {
  switch (command) {
    case OpCommand::kCmdBuild: return "vkCmdBuildAccelerationStructuresKHR";
    case OpCommand::kCmdBuildIndirect: return "vkCmdBuildAccelerationStructuresIndirectKHR";
    case OpCommand::kHostBuild: return "vkBuildAccelerationStructuresKHR";
    case OpCommand::kCmdCopy: return "vkCmdCopyAccelerationStructureKHR";
    case OpCommand::kHostCopy: return "vkCopyAccelerationStructureKHR";
    case OpCommand::kCmdCopyToMemory: return "vkCmdCopyAccelerationStructureToMemoryKHR";
    case OpCommand::kHostCopyToMemory: return "vkCopyAccelerationStructureToMemoryKHR";
    case OpCommand::kCmdCopyMemoryTo: return "vkCmdCopyMemoryToAccelerationStructureKHR";
    case OpCommand::kHostCopyMemoryTo: return "vkCopyMemoryToAccelerationStructureKHR";
    case OpCommand::kCmdWriteProperties: return "vkCmdWriteAccelerationStructuresPropertiesKHR";
    case OpCommand::kHostWriteProperties: return "vkWriteAccelerationStructuresPropertiesKHR";
    case OpCommand::kCmdBuildNV: return "vkCmdBuildAccelerationStructureNV";
    case OpCommand::kCmdCopyNV: return "vkCmdCopyAccelerationStructureNV";
    case OpCommand::kCmdWritePropertiesNV: return "vkCmdWriteAccelerationStructuresPropertiesNV";
    case OpCommand::kCmdTraceRays: return "vkCmdTraceRaysKHR";
    case OpCommand::kCmdTraceRaysIndirect: return "vkCmdTraceRaysIndirectKHR";
    case OpCommand::kCmdTraceRaysIndirect2: return "vkCmdTraceRaysIndirect2KHR";
    case OpCommand::kCmdDispatch: return "vkCmdDispatch";
    case OpCommand::kCmdDispatchIndirect: return "vkCmdDispatchIndirect";
    case OpCommand::kCmdDispatchBase: return "vkCmdDispatchBase";
    case OpCommand::kCmdDraw: return "vkCmdDraw";
    case OpCommand::kCmdDrawIndexed: return "vkCmdDrawIndexed";
    case OpCommand::kCmdDrawIndirect: return "vkCmdDrawIndirect";
    case OpCommand::kCmdDrawIndexedIndirect: return "vkCmdDrawIndexedIndirect";
    case OpCommand::kCmdDrawIndirectCount: return "vkCmdDrawIndirectCount";
    case OpCommand::kCmdDrawIndexedIndirectCount: return "vkCmdDrawIndexedIndirectCount";
    case OpCommand::kCmdDrawMultiEXT: return "vkCmdDrawMultiEXT";
    case OpCommand::kCmdDrawMultiIndexedEXT: return "vkCmdDrawMultiIndexedEXT";
    case OpCommand::kCmdDrawIndirectByteCountEXT: return "vkCmdDrawIndirectByteCountEXT";
    case OpCommand::kCmdDrawMeshTasksEXT: return "vkCmdDrawMeshTasksEXT";
    case OpCommand::kCmdDrawMeshTasksIndirectEXT: return "vkCmdDrawMeshTasksIndirectEXT";
    case OpCommand::kCmdDrawMeshTasksIndirectCountEXT: return "vkCmdDrawMeshTasksIndirectCountEXT";
    case OpCommand::kCount: break;
  }
  return "?";
}

const char* OpCommandArrayName(OpCommand command) {
  switch (command) {
    case OpCommand::kCmdBuild:
    case OpCommand::kCmdBuildIndirect:
    case OpCommand::kHostBuild: return "pInfos";
    case OpCommand::kCmdWriteProperties:
    case OpCommand::kHostWriteProperties:
    case OpCommand::kCmdWritePropertiesNV: return "pAccelerationStructures";
    case OpCommand::kCmdCopyNV: return "";
    default: return "pInfo";
  }
}

namespace {

std::string Ordinal(uint32_t n) {
  const uint32_t tens = n % 100;
  const char* suffix = "th";
  if (tens < 11 || tens > 13) {
    if (n % 10 == 1) suffix = "st";
    if (n % 10 == 2) suffix = "nd";
    if (n % 10 == 3) suffix = "rd";
  }
  return std::to_string(n) + suffix;
}

std::string Handle(const void* handle) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "0x%" PRIxPTR, reinterpret_cast<uintptr_t>(handle));
  return buf;
}

bool IsArray(OpCommand command) {
  const std::string_view name = OpCommandArrayName(command);
  return name != "pInfo" && !name.empty();
}

}  // namespace

std::string DescribeOrigin(const OpOrigin& origin) {
  std::string text;
  if (IsArray(origin.command)) {
    text.append(OpCommandArrayName(origin.command)).append("[").append(std::to_string(origin.element)).append("] of ");
  }
  if (!origin.command_buffer) {
    text.append("the ").append(OpCommandName(origin.command)).append(" call");
    return text;
  }
  text.append("the ").append(Ordinal(origin.ordinal)).append(" ").append(OpCommandName(origin.command));
  text.append(" in VkCommandBuffer ").append(Handle(origin.command_buffer));
  if (origin.executed_by) {
    text.append(" (a secondary executed by VkCommandBuffer ").append(Handle(origin.executed_by)).append(")");
  }
  return text;
}

void OpBatch::Clear() {
  ops_.clear();
  geometries_.clear();
  touches_.clear();
  traced_.clear();
  applied_snapshots_.clear();
  lost_ = false;
}

namespace {

// Infos of at least this many geometries (from pGeometries) are appended by AppendInPlace; fewer one by one,
// which costs less than the out-of-line resize for one or two.
constexpr uint32_t kWrittenInPlaceFrom = 8;

}  // namespace

void GeometryRecord::Read(const VkAccelerationStructureGeometryKHR& geometry, uint32_t count, bool count_known) {
  type = geometry.geometryType;
  flags = geometry.flags;
  primitive_count = count;
  primitive_count_known = count_known;
  if (geometry.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VkAccelerationStructureGeometryTrianglesDataKHR& t = geometry.geometry.triangles;
    vertex_format = t.vertexFormat;
    index_type = t.indexType;
    max_vertex = t.maxVertex;
    // The union's device and host members share storage: non-null either way reads as a non-zero address.
    has_transform = t.transformData.deviceAddress != 0;
  } else {
    vertex_format = VK_FORMAT_UNDEFINED;
    index_type = VK_INDEX_TYPE_NONE_KHR;
    max_vertex = 0;
    has_transform = false;
  }
}

// Grows the array once and writes the records in place (the capacity was reserved): per geometry, push_back's
// capacity test and its copy of the record cost more than the record itself.
void OpBatch::AppendInPlace(const VkAccelerationStructureBuildGeometryInfoKHR& info,
                            const VkAccelerationStructureBuildRangeInfoKHR* info_ranges) {
  const std::size_t first = geometries_.size();
  geometries_.resize(first + info.geometryCount);
  GeometryRecord* out = geometries_.data() + first;
  // Without ranges every count reads the same zero (stride 0): the loop does not branch on it.
  static constexpr uint32_t kNoCount = 0;
  const char* count = info_ranges ? reinterpret_cast<const char*>(&info_ranges[0].primitiveCount)
                                  : reinterpret_cast<const char*>(&kNoCount);
  const std::size_t stride = info_ranges ? sizeof(VkAccelerationStructureBuildRangeInfoKHR) : 0;
  const bool known = info_ranges != nullptr;
  for (uint32_t j = 0; j < info.geometryCount; ++j, count += stride) {
    out[j].Read(info.pGeometries[j], *reinterpret_cast<const uint32_t*>(count), known);
  }
}

void OpBatch::AppendBuilds(const OpOrigin& origin, uint32_t info_count,
                           const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                           const VkAccelerationStructureBuildRangeInfoKHR* const* ranges, CaptureLog* log,
                           const uint32_t* captured, uint64_t max_geometry_count, bool touches) {
  for (uint32_t i = 0; i < info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = infos[i];
    const bool has_geometries =
        (info.pGeometries || info.ppGeometries) && GeometryCountWithinLimit(info, max_geometry_count);
    if (has_geometries) {
      // Room for the info's geometries at once (growing geometrically, as push_back would: a reserve of the
      // exact size per info would copy the whole batch on every call). Before the operation is appended, so
      // that an allocation failure leaves no operation without its geometries.
      const std::size_t needed = geometries_.size() + info.geometryCount;
      if (needed > geometries_.capacity()) geometries_.reserve(std::max(needed, 2 * geometries_.capacity()));
    }
    // In place, each member written once: an AsOp is large, and most of it stays at its defaults.
    AsOp& op = ops_.emplace_back(origin, i, info, static_cast<uint32_t>(geometries_.size()));
    if (captured && captured[i] != 0) {
      op.capture_log = log;
      op.capture_info = captured[i] - 1;
    }
    if (!has_geometries && info.geometryCount != 0) op.geometries_unreadable = true;
    if (has_geometries && info.geometryCount != 0) {
      // Whether the info has ranges is decided once, not per geometry.
      const VkAccelerationStructureBuildRangeInfoKHR* info_ranges = ranges ? ranges[i] : nullptr;
      if (info.pGeometries && info.geometryCount >= kWrittenInPlaceFrom) {
        AppendInPlace(info, info_ranges);
      } else {
        for (uint32_t j = 0; j < info.geometryCount; ++j) {
          const VkAccelerationStructureGeometryKHR* geometry =
              info.pGeometries ? &info.pGeometries[j] : info.ppGeometries[j];
          if (!geometry) {  // every check family guards this; the record must too
            op.geometries_unreadable = true;
            geometries_.resize(op.first_geometry);
            break;
          }
          geometries_.push_back(
              GeometryRecord(*geometry, info_ranges ? info_ranges[j].primitiveCount : 0, info_ranges != nullptr));
        }
      }
    }
    if (op.geometries_unreadable || !has_geometries) op.geometry_count = 0;
    // Device builds only: a host build's addresses are host pointers, and it completes within its call.
    if (touches && origin.command != OpCommand::kHostBuild && has_geometries) {
      AppendTouches(static_cast<uint32_t>(ops_.size() - 1), info);
    }
  }
}

const char* TouchRoleName(TouchRole role) {
  switch (role) {
    case TouchRole::kScratch:
      return "scratchData";
    case TouchRole::kVertices:
      return "vertexData";
    case TouchRole::kIndices:
      return "indexData";
    case TouchRole::kTransform:
      return "transformData";
    case TouchRole::kAabbs:
      return "aabbs data";
    case TouchRole::kInstances:
      return "instances data";
    case TouchRole::kSerialized:
      return "serialized bytes";
  }
  return "address";
}

void OpBatch::AppendTrace(const OpOrigin& origin, const TracedBinding* bindings, uint32_t count) {
  AsOp op;
  op.kind = OpKind::kTrace;
  op.origin = origin;
  op.first_geometry = static_cast<uint32_t>(traced_.size());
  op.geometry_count = count;
  if (count != 0) std::memcpy(traced_.Extend(count), bindings, count * sizeof(TracedBinding));
  ops_.push_back(op);
}

namespace {

// One geometry of an NV build as a KHR build's record: its primitives are its triangles (indices, else vertices, in
// threes) or AABBs.
GeometryRecord NvGeometryRecord(const VkGeometryNV& g) {
  GeometryRecord r;
  r.type = g.geometryType;
  r.flags = g.flags;
  r.vertex_format = VK_FORMAT_UNDEFINED;
  r.index_type = VK_INDEX_TYPE_NONE_KHR;
  r.max_vertex = 0;
  r.has_transform = false;
  r.primitive_count_known = true;
  if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_NV) {
    const VkGeometryTrianglesNV& t = g.geometry.triangles;
    r.vertex_format = t.vertexFormat;
    r.index_type = t.indexType;
    r.max_vertex = t.vertexCount == 0 ? 0 : t.vertexCount - 1;
    r.has_transform = t.transformData != VK_NULL_HANDLE;
    r.primitive_count = (t.indexType == VK_INDEX_TYPE_NONE_NV ? t.vertexCount : t.indexCount) / 3;
  } else {
    r.primitive_count = g.geometry.aabbs.numAABBs;
  }
  return r;
}

}  // namespace

void OpBatch::AppendNvBuild(const OpOrigin& origin, const VkAccelerationStructureInfoNV& info, bool update,
                            VkAccelerationStructureKHR dst, VkAccelerationStructureKHR src,
                            uint64_t max_geometry_count) {
  const bool top = info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV;
  const bool walkable = top || info.geometryCount == 0 ||
                        (info.pGeometries && (max_geometry_count == 0 || info.geometryCount <= max_geometry_count));
  const uint32_t count = top ? 1 : (walkable ? info.geometryCount : 0);
  geometries_.reserve(geometries_.size() + count);  // before the operation: a failure leaves none half-appended
  AsOp& op = ops_.emplace_back();
  op.origin = origin;
  op.mode = update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  op.src = update ? src : VK_NULL_HANDLE;
  op.dst = dst;
  op.flags = info.flags;
  op.type = info.type;
  op.first_geometry = static_cast<uint32_t>(geometries_.size());
  op.geometry_count = count;
  op.geometries_unreadable = !walkable;
  if (top) {
    GeometryRecord instances;
    instances.type = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    instances.flags = 0;
    instances.vertex_format = VK_FORMAT_UNDEFINED;
    instances.index_type = VK_INDEX_TYPE_NONE_KHR;
    instances.max_vertex = 0;
    instances.primitive_count = info.instanceCount;
    instances.has_transform = false;
    instances.primitive_count_known = true;
    geometries_.push_back(instances);
    return;
  }
  for (uint32_t j = 0; j < count; ++j) geometries_.push_back(NvGeometryRecord(info.pGeometries[j]));
}

void OpBatch::Append(const AsOp& op) {
  ops_.push_back(op);
  if ((op.kind == OpKind::kSerialize || op.kind == OpKind::kDeserialize) && op.memory.device_address != 0 &&
      op.origin.command_buffer != VK_NULL_HANDLE) {
    const uint32_t index = static_cast<uint32_t>(ops_.size() - 1);
    touches_.push_back(AddressTouch{op.memory.device_address, index, TouchRole::kSerialized});
  }
}

namespace {

// Writes one touch at w; the next is written past it only when its address is non-zero. A plain function of
// pointers, so that the loop keeps its write position in a register.
[[gnu::always_inline]] inline AddressTouch* Put(AddressTouch* w, VkDeviceAddress address, uint32_t op, TouchRole role) {
  w->address = address;
  w->op = op;
  w->role = role;
  return w + (address != 0);
}

// The addresses of one geometry (`g` read once).
[[gnu::always_inline]] inline AddressTouch* PutGeometry(AddressTouch* w, const VkAccelerationStructureGeometryKHR& g,
                                                        uint32_t op) {
  if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
    w = Put(w, t.vertexData.deviceAddress, op, TouchRole::kVertices);
    w = Put(w, t.indexType != VK_INDEX_TYPE_NONE_KHR ? t.indexData.deviceAddress : 0, op, TouchRole::kIndices);
    return Put(w, t.transformData.deviceAddress, op, TouchRole::kTransform);
  }
  if (g.geometryType == VK_GEOMETRY_TYPE_AABBS_KHR) {
    return Put(w, g.geometry.aabbs.data.deviceAddress, op, TouchRole::kAabbs);
  }
  if (g.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
    return Put(w, g.geometry.instances.data.deviceAddress, op, TouchRole::kInstances);
  }
  return w;
}

}  // namespace

// Written in place into room for every address the info may name (scratch, then at most three per geometry), then
// cut to what was written: per geometry, push_back's capacity test costs more than the touch itself.
void OpBatch::AppendTouches(uint32_t op, const VkAccelerationStructureBuildGeometryInfoKHR& info) {
  const std::size_t first = touches_.size();
  AddressTouch* const out = touches_.Extend(1 + 3 * std::size_t{info.geometryCount});
  AddressTouch* w = Put(out, info.scratchData.deviceAddress, op, TouchRole::kScratch);
  if (info.pGeometries) {
    for (uint32_t j = 0; j < info.geometryCount; ++j) w = PutGeometry(w, info.pGeometries[j], op);
  } else {
    for (uint32_t j = 0; j < info.geometryCount && info.ppGeometries[j]; ++j) {
      w = PutGeometry(w, *info.ppGeometries[j], op);
    }
  }
  touches_.Truncate(first + static_cast<std::size_t>(w - out));
}

void OpBatch::AppendExecuted(const OpBatch& secondary, VkCommandBuffer primary) {
  if (secondary.lost_) lost_ = true;
  const uint32_t first_op = static_cast<uint32_t>(ops_.size());
  for (AddressTouch touch : secondary.touches_) {
    touch.op += first_op;
    touches_.push_back(touch);
  }
  const uint32_t base = static_cast<uint32_t>(geometries_.size());
  const uint32_t traced_base = static_cast<uint32_t>(traced_.size());
  geometries_.insert(geometries_.end(), secondary.geometries_.begin(), secondary.geometries_.end());
  for (const TracedBinding& traced : secondary.traced_) traced_.push_back(traced);
  for (AsOp op : secondary.ops_) {
    op.first_geometry += op.kind == OpKind::kTrace ? traced_base : base;
    // A secondary executed inside another secondary keeps the outermost primary that ran it.
    op.origin.executed_by = primary;
    ops_.push_back(op);
  }
}

}  // namespace asval
