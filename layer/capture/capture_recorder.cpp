#include "capture_recorder.h"

#include <algorithm>
#include <limits>

#include "asval/builder/vertex_format.h"
#include "asval/vertex_formats.h"
#include "structure_memory.h"

namespace asval {

namespace {

constexpr VkDeviceSize kNoBytes = std::numeric_limits<VkDeviceSize>::max();
constexpr VkDeviceSize kAabbBytes = sizeof(VkAabbPositionsKHR);  // 24
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64
constexpr VkDeviceSize kTransformBytes = sizeof(VkTransformMatrixKHR);                 // 48

VkDeviceSize Add(VkDeviceSize a, VkDeviceSize b) { return a > kNoBytes - b ? kNoBytes : a + b; }
VkDeviceSize Mul(VkDeviceSize a, VkDeviceSize b) { return b != 0 && a > kNoBytes / b ? kNoBytes : a * b; }

// One range to copy: from a device address into the capture log.
struct Source {
  VkDeviceAddress address;
  VkDeviceSize size;
  CapturedBytes* into;
  bool optional = false;  // not needed for the rules (a transform, for the warnings): skipped when not copyable
};

// The ranges geometry g reads (exactly the bytes the specification says a build consumes, from where it starts
// reading), with the captured geometry's parameters rewritten for bytes that start there. False when the
// geometry is not captured.
bool PlanGeometry(const VkAccelerationStructureGeometryKHR& g, const VkAccelerationStructureBuildRangeInfoKHR& r,
                  CapturedGeometry* out, std::vector<Source>& sources) {
  out->type = g.geometryType;
  out->range.primitiveCount = r.primitiveCount;
  const VkDeviceSize n = r.primitiveCount;
  if (g.geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VkAccelerationStructureGeometryTrianglesDataKHR& t = g.geometry.triangles;
    const VertexFormatInfo& format = VertexFormatFacts(t.vertexFormat);
    const int index_bytes = builder::IndexTypeBytes(t.indexType);  // the builder's: it reads them
    if (!format.decodable || index_bytes < 0) return false;
    out->vertex_format = t.vertexFormat;
    out->vertex_stride = t.vertexStride;
    out->index_type = t.indexType;
    if (n == 0) return true;
    if (t.vertexData.deviceAddress == 0) return false;
    if (t.transformData.deviceAddress != 0) {
      sources.push_back(Source{Add(t.transformData.deviceAddress, r.transformOffset), kTransformBytes, &out->transform,
                               true});
    }
    if (index_bytes == 0) {
      // Vertex k of the range is read at primitiveOffset + stride * (firstVertex + k); the last one for its size.
      const VkDeviceSize first = Add(r.primitiveOffset, Mul(t.vertexStride, r.firstVertex));
      const VkDeviceSize bytes = Add(Mul(t.vertexStride, Mul(3, n) - 1), format.vertexBytes);
      out->max_vertex = t.maxVertex >= r.firstVertex ? t.maxVertex - r.firstVertex : 0;
      sources.push_back(Source{Add(t.vertexData.deviceAddress, first), bytes, &out->data});
    } else {
      if (t.indexData.deviceAddress == 0) return false;
      // Indices from primitiveOffset; vertices index + firstVertex up to maxVertex, from vertexData.
      out->max_vertex = t.maxVertex;
      out->range.firstVertex = r.firstVertex;
      sources.push_back(Source{Add(t.indexData.deviceAddress, r.primitiveOffset), Mul(Mul(3, n), index_bytes),
                               &out->indices});
      sources.push_back(
          Source{t.vertexData.deviceAddress, Add(Mul(t.vertexStride, t.maxVertex), format.vertexBytes), &out->data});
    }
    return true;
  }
  if (g.geometryType == VK_GEOMETRY_TYPE_AABBS_KHR) {
    const VkAccelerationStructureGeometryAabbsDataKHR& a = g.geometry.aabbs;
    out->aabb_stride = a.stride;
    if (n == 0) return true;
    if (a.data.deviceAddress == 0) return false;
    sources.push_back(
        Source{Add(a.data.deviceAddress, r.primitiveOffset), Add(Mul(a.stride, n - 1), kAabbBytes), &out->data});
    return true;
  }
  if (g.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR) {
    const VkAccelerationStructureGeometryInstancesDataKHR& in = g.geometry.instances;
    // Arrays of pointers: the pointers only (their alignment is a rule); where they point is known on the device
    // alone, so the records themselves, and with them the references and the activity, stay unknown.
    out->array_of_pointers = in.arrayOfPointers == VK_TRUE;
    if (n == 0) return true;
    if (in.data.deviceAddress == 0) return false;
    const VkDeviceSize record_bytes = out->array_of_pointers ? sizeof(VkDeviceAddress) : kInstanceBytes;
    sources.push_back(Source{Add(in.data.deviceAddress, r.primitiveOffset), Mul(record_bytes, n), &out->data});
    return true;
  }
  return false;
}

// The buffer a range can be copied from: bound, created copyable by the layer, holding the whole range.
std::optional<AddressHit> CopyableBuffer(const DeviceState& state, VkDeviceAddress address, VkDeviceSize size) {
  return state.buffer_addresses.FindCovering(address, size, [&](VkBuffer buffer) {
    std::optional<std::shared_ptr<const BufferState>> b = state.buffers.find(buffer);
    return b && *b && (*b)->bound && (*b)->capture_source;
  });
}

struct Copy {
  VkBuffer src;
  VkBuffer dst;
  VkBufferCopy region;
};

void RecordCopies(const CaptureContext& ctx, VkCommandBuffer cb, const std::vector<Copy>& copies) {
  // Earlier writes of any kind (the app's own copies, fills, shaders) become visible to the transfer read.
  VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  before.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  before.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  ctx.next.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &before, 0,
                              nullptr, 0, nullptr);
  for (const Copy& c : copies) ctx.next.CmdCopyBuffer(cb, c.src, c.dst, 1, &c.region);
  // The copies are visible to the host once the submission completes; later commands (writes of the inputs
  // included) wait for the reads. Later copies into the same capture bytes (a secondary command buffer executed
  // twice, whose capture is then unknown anyway) are ordered after these writes too: without TRANSFER_WRITE
  // here they would race with them (a write-after-write hazard that synchronization validation reports).
  VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  after.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  after.dstAccessMask = VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  ctx.next.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT,
                              VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &after, 0, nullptr,
                              0, nullptr);
}

// The destinations of a build command of several infos, for the rules about its top-level infos' instances and
// its other destinations (None-03407, dstAccelerationStructure-03706), judged once the instances are captured.
// The bytes each build writes are its accelerationStructureSize, as the size cache holds it: the command's
// validation has just looked it up (or asked the driver). A size or memory not known leaves the span unknown.
void ResolveDestinations(const DeviceState& state, uint32_t info_count,
                         const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                         const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                         std::vector<CommandDestination>& out) {
  out.assign(info_count, CommandDestination{});
  for (uint32_t i = 0; i < info_count; ++i) {
    CommandDestination& d = out[i];
    d.handle = infos[i].dstAccelerationStructure;
    d.element = i;
    const std::optional<StructureMemory> memory = MemoryOfStructure(state, d.handle);
    if (!memory) continue;
    d.address = memory->structure->device_address;
    BuildSignature signature;
    signature.info = &infos[i];
    BuildSizes sizes;
    if (!ranges[i] && infos[i].geometryCount != 0) continue;
    signature.counts = ranges[i] ? &ranges[i][0].primitiveCount : nullptr;
    signature.count_stride = sizeof(VkAccelerationStructureBuildRangeInfoKHR);
    if (infos[i].geometryCount != 0 && !state.build_sizes.Find(signature, &sizes)) continue;
    if (std::optional<MemorySpan> span = memory->Span(sizes.acceleration_structure_size)) d.accessed = *span;
  }
}

// What the range rules need of an indirect build's geometry j (pIndirectDeviceAddresses-03651): its range is read
// by the device, so it is judged at completion against the geometry as the app recorded it, copied now (the app's
// structures need not outlive the call).
void KeepRangeFacts(const VkAccelerationStructureBuildGeometryInfoKHR& info, uint32_t j, CapturedGeometry* out) {
  const VkAccelerationStructureGeometryKHR* g =
      info.pGeometries ? &info.pGeometries[j] : info.ppGeometries ? info.ppGeometries[j] : nullptr;
  if (!g) return;  // range_facts stays false: judged by no one, counted
  out->type = g->geometryType;
  if (g->geometryType == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VkAccelerationStructureGeometryTrianglesDataKHR& t = g->geometry.triangles;
    out->vertex_format = t.vertexFormat;
    out->index_type = t.indexType;
    out->max_vertex = t.maxVertex;
  }
  out->range_facts = true;
}

}  // namespace

bool CaptureIndirectRanges(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                           uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                           const VkDeviceAddress* addresses, const uint32_t* strides,
                           const uint32_t* const* max_primitive_counts, std::vector<uint32_t>& captured) {
  captured.clear();
  if (ctx.mode == kCaptureOff || !infos || !addresses || !strides || !max_primitive_counts || !ctx.next.CmdCopyBuffer ||
      !ctx.next.CmdPipelineBarrier) {
    return false;
  }
  // Kept from call to call on this thread (nothing here calls back into the app): no allocation per call.
  thread_local std::vector<Copy> copies;
  // No geometry data (only the range infos are captured): the facts their rules need.
  thread_local std::vector<CapturedGeometry> planned;
  copies.clear();
  for (uint32_t i = 0; i < info_count; ++i) {
    const uint32_t n = infos[i].geometryCount;
    if (n == 0 || !max_primitive_counts[i] || addresses[i] == 0) continue;
    if (captured.empty()) captured.assign(info_count, 0);
    CaptureLog& log = recording.CaptureLogFor(ctx.pool.shared_from_this());
    CapturedInfo entry;
    entry.indirect = true;
    entry.geometry_count = n;
    entry.indirect_stride = strides[i];
    const VkDeviceSize bytes = Add(Mul(strides[i], n - 1), sizeof(VkAccelerationStructureBuildRangeInfoKHR));
    const bool within_budget = Add(log.bytes_captured, bytes) <= ctx.budget_bytes;
    if (!within_budget) ctx.counters.infos_over_budget.fetch_add(1, std::memory_order_relaxed);
    const std::optional<AddressHit> hit =
        within_budget ? CopyableBuffer(ctx.state, addresses[i], bytes) : std::nullopt;
    if (hit && log.Reserve(bytes, &entry.ranges)) {
      copies.push_back(Copy{hit->buffer, log.BufferOf(entry.ranges),
                            VkBufferCopy{addresses[i] - hit->base, entry.ranges.offset, bytes}});
      ctx.counters.infos_captured.fetch_add(1, std::memory_order_relaxed);
      ctx.counters.bytes_captured.fetch_add(bytes, std::memory_order_relaxed);
    } else {
      entry.complete = false;
      ctx.counters.infos_not_captured.fetch_add(1, std::memory_order_relaxed);
    }
    planned.assign(n, CapturedGeometry{});
    for (uint32_t j = 0; j < n; ++j) KeepRangeFacts(infos[i], j, &planned[j]);
    captured[i] = log.AddInfo(entry, planned.data(), max_primitive_counts[i], bytes);
  }
  if (!copies.empty()) RecordCopies(ctx, cb, copies);
  return !captured.empty();
}

bool CaptureBuildInputs(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                        uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                        const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                        std::vector<uint32_t>& captured) {
  captured.clear();
  if (!infos || !ranges || !ctx.next.CmdCopyBuffer || !ctx.next.CmdPipelineBarrier) return false;
  // Kept from call to call on this thread (nothing here calls back into the app): no allocation per call.
  thread_local std::vector<Copy> copies;
  thread_local std::vector<Source> sources;
  thread_local std::vector<CapturedGeometry> planned;  // the info's geometries, before they join the log
  thread_local std::vector<CommandDestination> destinations;
  copies.clear();
  bool destinations_logged = false;
  uint32_t first_destination = 0;
  for (uint32_t i = 0; i < info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = infos[i];
    if (!NeedsCapture(ctx.mode, info)) continue;
    if (captured.empty()) captured.assign(info_count, 0);
    const VkAccelerationStructureBuildRangeInfoKHR* info_ranges = ranges[i];
    // Motion instances (VK_NV_ray_tracing_motion_blur) have other records: not captured yet.
    const bool motion = (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0;
    if (!info_ranges || (!info.pGeometries && !info.ppGeometries) || motion) {
      ctx.counters.infos_not_captured.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    CaptureLog& log = recording.CaptureLogFor(ctx.pool.shared_from_this());
    CapturedInfo entry;
    entry.geometry_count = info.geometryCount;
    entry.element = i;
    if (info_count > 1 && info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
      if (!destinations_logged) {  // once per command, shared by its top-level infos
        ResolveDestinations(ctx.state, info_count, infos, ranges, destinations);
        first_destination = log.AddDestinations(destinations.data(), info_count);
        destinations_logged = true;
      }
      entry.first_destination = first_destination;
      entry.destination_count = info_count;
    }
    planned.assign(info.geometryCount, CapturedGeometry{});
    sources.clear();
    for (uint32_t j = 0; j < info.geometryCount && entry.complete; ++j) {
      const VkAccelerationStructureGeometryKHR* g = info.pGeometries ? &info.pGeometries[j] : info.ppGeometries[j];
      entry.complete = g && PlanGeometry(*g, info_ranges[j], &planned[j], sources);
    }
    VkDeviceSize total = 0;
    for (const Source& s : sources) total = Add(total, s.size);
    if (entry.complete && Add(log.bytes_captured, total) > ctx.budget_bytes) {
      entry.complete = false;
      ctx.counters.infos_over_budget.fetch_add(1, std::memory_order_relaxed);
    }
    const std::size_t first_copy = copies.size();
    for (const Source& s : sources) {
      if (!entry.complete) break;
      const std::optional<AddressHit> hit = CopyableBuffer(ctx.state, s.address, s.size);
      if (!hit && s.optional) continue;
      if (!hit || !log.Reserve(s.size, s.into)) {
        entry.complete = false;
        break;
      }
      copies.push_back(Copy{hit->buffer, log.BufferOf(*s.into), VkBufferCopy{s.address - hit->base, s.into->offset, s.size}});
    }
    if (!entry.complete) {
      copies.resize(first_copy);
      ctx.counters.infos_not_captured.fetch_add(1, std::memory_order_relaxed);
    } else {
      ctx.counters.infos_captured.fetch_add(1, std::memory_order_relaxed);
      ctx.counters.bytes_captured.fetch_add(total, std::memory_order_relaxed);
    }
    captured[i] = log.AddInfo(entry, planned.data(), nullptr, total);
  }
  if (!copies.empty()) RecordCopies(ctx, cb, copies);
  return !captured.empty();
}

}  // namespace asval
