#include "capture_recorder.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "asval/builder/vertex_format.h"
#include "asval/vertex_formats.h"
#include "capture_plan.h"
#include "capture_reducer.h"
#include "history.h"
#include "structure_memory.h"

namespace asval {

namespace {

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

// One reducing dispatch (capture_reducer.h): the pipeline of the slab holding its job, and where the job is.
struct Dispatch {
  VkPipeline pipeline;
  uint32_t job_y;  // the job's offset in 16-byte units: low 15 bits
  uint32_t job_z;  // ... and the rest
  uint32_t groups;
};

// The captures of one command, between two barriers: copies, then the reducing dispatches (after which the app's
// compute pipeline, `app_pipeline`, is bound again).
void RecordCaptures(const CaptureContext& ctx, VkCommandBuffer cb, const std::vector<Copy>& copies,
                    const std::vector<Dispatch>& dispatches, VkPipeline app_pipeline) {
  const bool reduces = !dispatches.empty();
  // Earlier writes of any kind (the app's own copies, fills, shaders) become visible to the transfer read (and to
  // the layer's shader, which reads the inputs through their device addresses).
  VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  before.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  before.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | (reduces ? VK_ACCESS_SHADER_READ_BIT : 0);
  ctx.next.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                              VK_PIPELINE_STAGE_TRANSFER_BIT | (reduces ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : 0), 0,
                              1, &before, 0, nullptr, 0, nullptr);
  for (const Copy& c : copies) ctx.next.CmdCopyBuffer(cb, c.src, c.dst, 1, &c.region);
  if (reduces) {
    VkPipeline bound = VK_NULL_HANDLE;
    for (const Dispatch& d : dispatches) {
      if (d.pipeline != bound) ctx.next.CmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, bound = d.pipeline);
      ctx.next.CmdDispatchBase(cb, 0, d.job_y, d.job_z, d.groups, 1, 1);
    }
    if (app_pipeline != VK_NULL_HANDLE) ctx.next.CmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, app_pipeline);
  }
  // The copies (and the dispatches' writes) are visible to the host once the submission completes; later
  // commands (writes of the inputs included) wait for the reads. Later writes into the same capture bytes (a
  // secondary command buffer executed twice, whose capture is then unknown anyway) are ordered after these writes
  // too: without them here they would race (a write-after-write hazard that synchronization validation reports).
  VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  after.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | (reduces ? VK_ACCESS_SHADER_WRITE_BIT : 0);
  after.dstAccessMask =
      VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | (reduces ? VK_ACCESS_SHADER_WRITE_BIT : 0);
  ctx.next.CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | (reduces ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : 0),
                              VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &after, 0, nullptr,
                              0, nullptr);
}

void RecordCopies(const CaptureContext& ctx, VkCommandBuffer cb, const std::vector<Copy>& copies) {
  static const std::vector<Dispatch> kNone;
  RecordCaptures(ctx, cb, copies, kNone, VK_NULL_HANDLE);
}

// Whether geometry g's bytes (its `data`) can be reduced on the device instead of copied: triangles, AABBs, and
// instances given as an array of records, with strides the shader's 32-bit arithmetic holds.
bool Reducible(const CapturedGeometry& g) {
  const uint32_t n = g.range.primitiveCount;
  if (n == 0) return false;
  switch (g.type) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
      return g.vertex_stride <= UINT32_MAX && n <= UINT32_MAX / 3;
    case VK_GEOMETRY_TYPE_AABBS_KHR:
      return g.aabb_stride <= UINT32_MAX;
    case VK_GEOMETRY_TYPE_INSTANCES_KHR:
      return !g.array_of_pointers;
    default:
      return false;
  }
}

// The job reading geometry g in place: its bytes at `data` (where the copy would have started), its indices at
// `indices` (indexed triangles), its results at `out`.
ReduceJob MakeReduceJob(const CapturedGeometry& g, VkDeviceAddress data, VkDeviceAddress indices, VkDeviceAddress out) {
  ReduceJob job;
  job.count = g.range.primitiveCount;
  job.data = data;
  job.out = out;
  if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VertexFormatInfo& format = VertexFormatFacts(g.vertex_format);
    job.kind = ReduceJob::kTriangles;
    job.stride = static_cast<uint32_t>(g.vertex_stride);
    job.x_kind = !format.hasNaN                              ? ReduceJob::kNoNaN
                 : format.kind == ComponentKind::Float16 ? ReduceJob::kFloat16
                                                         : ReduceJob::kFloat32;
    job.components = std::min<uint32_t>(format.componentCount, 3);
    job.index_bytes = static_cast<uint32_t>(std::max(builder::IndexTypeBytes(g.index_type), 0));
    job.first_vertex = g.range.firstVertex;
    job.max_vertex = g.max_vertex;
    job.indices = indices;
  } else if (g.type == VK_GEOMETRY_TYPE_AABBS_KHR) {
    job.kind = ReduceJob::kAabbs;
    job.stride = static_cast<uint32_t>(g.aabb_stride);
  } else {
    job.kind = ReduceJob::kInstances;
    job.stride = sizeof(VkAccelerationStructureInstanceKHR);
  }
  return job;
}

// A bound buffer holding the whole range (the layer's shader reads it through its device address; no usage
// beyond the SHADER_DEVICE_ADDRESS that gave the address is needed).
std::optional<AddressHit> ReadableBuffer(const DeviceState& state, VkDeviceAddress address, VkDeviceSize size) {
  return state.buffer_addresses.FindCovering(address, size, [&](VkBuffer buffer) {
    std::optional<std::shared_ptr<const BufferState>> b = state.buffers.find(buffer);
    return b && *b && (*b)->bound;
  });
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

// Geometry g's `data` source read in place by the layer's dispatch: its results and its job reserved in the log,
// the job written, the dispatch added. False when it cannot be (no bound buffer holds the range, no room, a slab
// without a pipeline): the info is then not captured.
bool ReduceSource(CaptureLog& log, const CaptureSource& s, CapturedGeometry& g, const std::vector<CaptureSource>& sources,
                  const std::optional<AddressHit>& readable, std::vector<Dispatch>& dispatches) {
  if (!readable) return false;
  CapturedBytes job_bytes;
  if (!log.Reserve(ReducedBytes(g.type, g.range.primitiveCount), s.into) ||
      !log.Reserve(sizeof(ReduceJob), &job_bytes)) {
    return false;
  }
  const VkPipeline pipeline = log.ReducePipelineOf(job_bytes);
  const VkDeviceSize job16 = job_bytes.offset / 16;  // Reserve is 16-aligned
  if (pipeline == VK_NULL_HANDLE || (job16 >> 15) >= kReduceMaxGroups) return false;
  VkDeviceAddress indices = 0;  // the same geometry's index source (planned before its vertices)
  for (const CaptureSource& other : sources) {
    if (other.into == &g.indices) indices = other.address;
  }
  const ReduceJob job = MakeReduceJob(g, s.address, indices, log.AddressOf(*s.into));
  std::memcpy(log.WritableBytes(job_bytes), &job, sizeof(job));
  g.reduced = true;
  const uint32_t groups = static_cast<uint32_t>(std::min<VkDeviceSize>(
      (VkDeviceSize{g.range.primitiveCount} + kReducePrimitivesPerGroup - 1) / kReducePrimitivesPerGroup, kReduceMaxGroups));
  dispatches.push_back(Dispatch{pipeline, static_cast<uint32_t>(job16 & 0x7fff), static_cast<uint32_t>(job16 >> 15), groups});
  return true;
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
    const VkDeviceSize bytes =
        SaturatingAddBytes(SaturatingMulBytes(strides[i], n - 1), sizeof(VkAccelerationStructureBuildRangeInfoKHR));
    const bool within_budget = SaturatingAddBytes(log.bytes_captured, bytes) <= ctx.budget_bytes;
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
  const bool reduces = ctx.pool.reduces();
  // Kept from call to call on this thread (nothing here calls back into the app): no allocation per call.
  thread_local std::vector<Copy> copies;
  thread_local std::vector<Dispatch> dispatches;
  thread_local std::vector<CaptureSource> sources;
  thread_local std::vector<uint32_t> source_geometry;  // per source: its geometry
  thread_local std::vector<uint8_t> source_reduced;    // per source: read in place by the layer's dispatch
  thread_local std::vector<CapturedGeometry> planned;  // the info's geometries, before they join the log
  thread_local std::vector<CommandDestination> destinations;
  copies.clear();
  dispatches.clear();
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
    source_geometry.clear();
    for (uint32_t j = 0; j < info.geometryCount && entry.complete; ++j) {
      const VkAccelerationStructureGeometryKHR* g = info.pGeometries ? &info.pGeometries[j] : info.ppGeometries[j];
      entry.complete = g && PlanCapturedGeometry(*g, info_ranges[j], false, &planned[j], sources);
      source_geometry.resize(sources.size(), j);
    }
    // What each source costs: its bytes, or what the dispatch writes for it (and its job).
    source_reduced.assign(sources.size(), 0);
    VkDeviceSize total = 0;
    for (std::size_t k = 0; k < sources.size(); ++k) {
      const CapturedGeometry& g = planned[source_geometry[k]];
      source_reduced[k] = reduces && sources[k].into == &g.data && Reducible(g);
      total = SaturatingAddBytes(
          total, source_reduced[k] ? ReducedBytes(g.type, g.range.primitiveCount) + sizeof(ReduceJob) : sources[k].size);
    }
    if (entry.complete && SaturatingAddBytes(log.bytes_captured, total) > ctx.budget_bytes) {
      entry.complete = false;
      ctx.counters.infos_over_budget.fetch_add(1, std::memory_order_relaxed);
    }
    const std::size_t first_copy = copies.size();
    const std::size_t first_dispatch = dispatches.size();
    for (std::size_t k = 0; k < sources.size() && entry.complete; ++k) {
      const CaptureSource& s = sources[k];
      if (source_reduced[k]) {
        entry.complete = ReduceSource(log, s, planned[source_geometry[k]], sources, ReadableBuffer(ctx.state, s.address, s.size),
                                      dispatches);
        continue;
      }
      const std::optional<AddressHit> hit = CopyableBuffer(ctx.state, s.address, s.size);
      if (!hit && s.optional) continue;
      if (!hit || !log.Reserve(s.size, s.into)) {
        entry.complete = false;
        break;
      }
      copies.push_back(
          Copy{hit->buffer, log.BufferOf(*s.into), VkBufferCopy{s.address - hit->base, s.into->offset, s.size}});
    }
    if (!entry.complete) {
      copies.resize(first_copy);
      dispatches.resize(first_dispatch);
      ctx.counters.infos_not_captured.fetch_add(1, std::memory_order_relaxed);
    } else {
      ctx.counters.infos_captured.fetch_add(1, std::memory_order_relaxed);
      ctx.counters.bytes_captured.fetch_add(total, std::memory_order_relaxed);
    }
    captured[i] = log.AddInfo(entry, planned.data(), nullptr, total);
  }
  if (!copies.empty() || !dispatches.empty()) {
    RecordCaptures(ctx, cb, copies, dispatches, recording.compute_pipeline);
  }
  return !captured.empty();
}

uint32_t CaptureSerializedBlob(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                               VkDeviceAddress address, VkAccelerationStructureKHR src) {
  if (ctx.mode == kCaptureOff || address == 0 || !ctx.next.CmdCopyBuffer || !ctx.next.CmdPipelineBarrier) return 0;
  // The header (two UUIDs, then the serialized size, the deserialized size and the handle count): less than it
  // can never be hashed.
  constexpr VkDeviceSize kHeaderBytes = 2 * VK_UUID_SIZE + 3 * sizeof(uint64_t);
  // The copyable buffer holding `address` that reaches furthest past it. Inline hits: no allocation.
  AddressHits hits;
  ctx.state.buffer_addresses.FindContaining(address, hits);
  std::optional<AddressHit> from;
  VkDeviceSize capacity = 0;
  for (const AddressHit& hit : hits) {
    const VkDeviceSize remaining = hit.base + hit.size - address;
    if (remaining <= capacity) continue;
    std::optional<std::shared_ptr<const BufferState>> b = ctx.state.buffers.find(hit.buffer);
    if (!b || !*b || !(*b)->bound || !(*b)->capture_source) continue;
    from = hit;
    capacity = remaining;
  }
  if (!from) {
    ctx.counters.blobs_not_captured.fetch_add(1, std::memory_order_relaxed);
    return 0;
  }
  VkDeviceSize wanted = capacity;
  {
    // The size the layer knows, read under the history's lock (serializations are rare next to builds).
    const HistoryStore& store = ctx.state.history.store;
    std::unique_lock<std::mutex> lock = store.Lock();
    if (src != VK_NULL_HANDLE) {
      const AsHistory* h = store.Find(src);
      if (h && h->generation != 0 && h->serialization_size_generation == h->generation && h->serialization_size != 0) {
        wanted = std::min<VkDeviceSize>(wanted, h->serialization_size);
      }
    } else if (const SerializedBlob* blob = store.FindDeviceBlobAt(address)) {
      if (blob->span.end > blob->span.begin) wanted = std::min<VkDeviceSize>(wanted, blob->span.end - blob->span.begin);
    }
  }
  CaptureLog& log = recording.CaptureLogFor(ctx.pool.shared_from_this());
  const VkDeviceSize budget_left = log.bytes_captured < ctx.budget_bytes ? ctx.budget_bytes - log.bytes_captured : 0;
  const VkDeviceSize bytes = std::min(wanted, budget_left);
  CapturedBytes into;
  if (bytes < kHeaderBytes || !log.Reserve(bytes, &into)) {
    ctx.counters.blobs_not_captured.fetch_add(1, std::memory_order_relaxed);
    return 0;
  }
  // One copy: a single-element array of the thread's, as the builds' captures keep theirs (no allocation).
  thread_local std::vector<Copy> copies;
  copies.clear();
  copies.push_back(Copy{from->buffer, log.BufferOf(into), VkBufferCopy{address - from->base, into.offset, bytes}});
  RecordCopies(ctx, cb, copies);
  ctx.counters.blobs_captured.fetch_add(1, std::memory_order_relaxed);
  ctx.counters.bytes_captured.fetch_add(bytes, std::memory_order_relaxed);
  return log.AddBlob(into);
}

}  // namespace asval
