#include "capture_reduce_jobs.h"

#include <algorithm>
#include <cstring>

#include "asval/builder/vertex_format.h"
#include "asval/vertex_formats.h"
#include "capture_buffers.h"

namespace asval {

namespace {

// The job reading geometry g in place: its bytes at `data` (where the copy would have started), its indices at
// `indices` (indexed triangles) and its transform at `transform` (0: none), its results at `out`.
ReduceJob MakeReduceJob(const CapturedGeometry& g, VkDeviceAddress data, VkDeviceAddress indices,
                        VkDeviceAddress transform, VkDeviceAddress out) {
  ReduceJob job;
  job.count = g.range.primitiveCount;
  job.data = data;
  job.out = out;
  if (g.type == VK_GEOMETRY_TYPE_TRIANGLES_KHR) {
    const VertexFormatInfo& format = VertexFormatFacts(g.vertex_format);
    job.kind = ReduceJob::kTriangles;
    job.stride = static_cast<uint32_t>(g.vertex_stride);
    const ReduceJob::XKind x_kind = !format.hasNaN                              ? ReduceJob::kNoNaN
                                    : format.kind == ComponentKind::Float16 ? ReduceJob::kFloat16
                                                                            : ReduceJob::kFloat32;
    job.format = ReduceJob::Format(x_kind, std::min<uint32_t>(format.componentCount, 3),
                                   static_cast<uint32_t>(std::max(builder::IndexTypeBytes(g.index_type), 0)));
    job.first_vertex = g.range.firstVertex;
    job.max_vertex = g.max_vertex;
    job.indices = indices;
    job.transform = transform;
  } else if (g.type == VK_GEOMETRY_TYPE_AABBS_KHR) {
    job.kind = ReduceJob::kAabbs;
    job.stride = static_cast<uint32_t>(g.aabb_stride);
  } else if (g.array_of_pointers) {
    job.kind = ReduceJob::kGatherInstances;
    job.stride = sizeof(VkDeviceAddress);
  } else {
    job.kind = ReduceJob::kInstances;
    job.stride = sizeof(VkAccelerationStructureInstanceKHR);
  }
  return job;
}

// An indirect build's job: the shader reads the geometry's range info at `range` first (0: a direct build's).
ReduceJob Indirect(ReduceJob job, VkDeviceAddress range) {
  if (range == 0) return job;
  job.kind |= ReduceJob::kIndirect;
  job.range = range;
  return job;
}

// What must lie in a bound buffer for the dispatch to read source s: all of it, or for an indirect build's geometry
// (its offset and count on the device) where it starts, one word (the build reads from there what the dispatch
// reads).
VkDeviceSize ReadableExtent(const CaptureSource& s, VkDeviceAddress indirect_range) {
  return indirect_range == 0 ? s.size : std::min<VkDeviceSize>(s.size, 4);
}

}  // namespace

bool Reducible(const CapturedGeometry& g) {
  const uint32_t n = g.range.primitiveCount;
  if (n == 0) return false;
  switch (g.type) {
    case VK_GEOMETRY_TYPE_TRIANGLES_KHR:  // the shader counts index bytes in 32 bits, and reads one vertex set
      return g.vertex_stride <= UINT32_MAX && n <= UINT32_MAX / 12 && !g.motion;
    case VK_GEOMETRY_TYPE_AABBS_KHR:
      return g.aabb_stride <= UINT32_MAX;
    case VK_GEOMETRY_TYPE_INSTANCES_KHR:
      return !g.array_of_pointers;
    default:
      return false;
  }
}

namespace {

bool TakeBlock(JobBlock& block, CaptureLog& log, uint32_t jobs, VkPipeline pipeline) {
  CapturedBytes bytes;
  if (jobs == 0 || jobs > kReduceMaxJobsPerDispatch ||
      !log.Reserve(VkDeviceSize{jobs} * sizeof(ReduceJob) + 48, &bytes)) {  // 48: room to align to 64
    return false;
  }
  const VkDeviceSize first = (bytes.offset + 63) / 64;
  const uint32_t table_index = log.TableIndexOf(bytes);
  if (table_index == UINT32_MAX || first + jobs > kReduceJobsPerSlab) return false;
  block.slots = log.WritableBytes(bytes) + (first * 64 - bytes.offset);
  block.dispatch = CaptureDispatch{pipeline, table_index << 16 | static_cast<uint32_t>(first), 0, 0};
  block.capacity = jobs;
  return block.ok = true;
}

}  // namespace

bool AcquireJobs(JobBlock& block, CaptureLog& log, uint32_t jobs, uint32_t wanted, VkPipeline pipeline) {
  block = JobBlock{};
  if (pipeline == VK_NULL_HANDLE) return false;
  wanted = std::min(std::max(wanted, jobs), kReduceMaxJobsPerDispatch);
  // The larger block first; a slab's job table may have room for the jobs only.
  return (wanted > jobs && TakeBlock(block, log, wanted, pipeline)) || TakeBlock(block, log, jobs, pipeline);
}

void AddJob(JobBlock& block, const ReduceJob& job) {
  std::memcpy(block.slots + VkDeviceSize{block.dispatch.jobs} * sizeof(ReduceJob), &job, sizeof(job));
  ++block.dispatch.jobs;
  const VkDeviceSize groups = (VkDeviceSize{job.count} + kReducePrimitivesPerGroup - 1) / kReducePrimitivesPerGroup;
  block.dispatch.groups =
      std::max(block.dispatch.groups, static_cast<uint32_t>(std::min<VkDeviceSize>(groups, kReduceMaxGroups)));
}

bool Gatherable(const CapturedGeometry& g) {
  const uint32_t n = g.range.primitiveCount;
  return g.type == VK_GEOMETRY_TYPE_INSTANCES_KHR && g.array_of_pointers && n != 0 && n <= UINT32_MAX / 72;
}

bool GatherInstancePointers(const DeviceState& state, CaptureLog& log, CapturedGeometry& g,
                            const CaptureSource& pointers, JobBlock& block, CaptureSkip* why,
                            VkDeviceAddress indirect_range) {
  if (!BoundBufferCovering(state, pointers.address, ReadableExtent(pointers, indirect_range))) {
    *why = CaptureSkip::kUnknownAddress;
    return false;
  }
  CapturedBytes out;
  if (block.dispatch.jobs >= block.capacity) {  // the block was sized for every job: not reached
    *why = CaptureSkip::kCaptureMemoryFailed;
    return false;
  }
  if (!log.Reserve(GatheredBytes(g.range.primitiveCount), &out)) {
    state.capture_counters.failures.capture_memory_failures.fetch_add(1, std::memory_order_relaxed);  // no slab
    *why = CaptureSkip::kCaptureMemoryFailed;
    return false;
  }
  const VkDeviceSize pointer_bytes = 8 * VkDeviceSize{g.range.primitiveCount};
  g.pointers = CapturedBytes{out.slab, out.offset, pointer_bytes, true};
  g.data = CapturedBytes{out.slab, out.offset + pointer_bytes, out.size - pointer_bytes, true};
  AddJob(block, Indirect(MakeReduceJob(g, pointers.address, 0, 0, log.AddressOf(out)), indirect_range));
  return true;
}

ReducedSources SourcesOf(const CapturedGeometry& g, const CaptureSource* first, const CaptureSource* last) {
  ReducedSources of;
  for (const CaptureSource* s = first; s != last; ++s) {
    if (s->into == &g.data) of.data = s;
    if (s->into == &g.indices) of.indices = s;
    if (s->into == &g.transform) of.transform = s;
  }
  return of;
}

VkDeviceSize ReducedCost(const CapturedGeometry& g, const ReducedSources& sources) {
  return ReducedBytes(g.type, g.range.primitiveCount, sources.indices != nullptr, sources.transform != nullptr) +
         sizeof(ReduceJob);
}

bool ReduceGeometry(const DeviceState& state, CaptureLog& log, CapturedGeometry& g, const ReducedSources& sources,
                    JobBlock& block, CaptureSkip* why, VkDeviceAddress indirect_range) {
  const auto readable = [&](const CaptureSource* s) {
    return s && BoundBufferCovering(state, s->address, ReadableExtent(*s, indirect_range)).has_value();
  };
  const CaptureSource* indices = sources.indices;
  const CaptureSource* transform = readable(sources.transform) ? sources.transform : nullptr;  // optional
  if (!readable(sources.data) || (indices && !readable(indices))) {
    *why = CaptureSkip::kUnknownAddress;
    return false;
  }
  if (block.dispatch.jobs >= block.capacity) {  // the block was sized for every job: not reached
    *why = CaptureSkip::kCaptureMemoryFailed;
    return false;
  }
  const uint32_t n = g.range.primitiveCount;
  CapturedBytes out;
  if (!log.Reserve(ReducedBytes(g.type, n, indices != nullptr, transform != nullptr), &out)) {
    state.capture_counters.failures.capture_memory_failures.fetch_add(1, std::memory_order_relaxed);  // no slab
    *why = CaptureSkip::kCaptureMemoryFailed;
    return false;
  }
  g.data = out;
  const VkDeviceSize bits = ReducedBitBytes(g.type, n);
  const VkDeviceSize hashes = indices ? ReducedHashBytes(n) : 0;  // the index hash's, per 64 triangles
  if (indices) g.indices = CapturedBytes{out.slab, out.offset + bits, hashes, true};
  if (transform) g.transform = CapturedBytes{out.slab, out.offset + bits + hashes, transform->size, true};
  g.reduced = true;
  AddJob(block, Indirect(MakeReduceJob(g, sources.data->address, indices ? indices->address : 0,
                                       transform ? transform->address : 0, log.AddressOf(out)),
                         indirect_range));
  return true;
}

}  // namespace asval
