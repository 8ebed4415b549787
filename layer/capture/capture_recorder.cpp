#include "capture_recorder.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <new>
#include <utility>

#include "asval/builder/vertex_format.h"
#include "asval/vertex_formats.h"
#include "capture_buffers.h"
#include "capture_plan.h"
#include "capture_recording.h"
#include "capture_reduce_jobs.h"
#include "capture_run_end.h"
#include "failure_injection.h"
#include "history.h"
#include "structure_memory.h"

namespace asval {

namespace {

// How the capture reads a geometry: copies of its ranges, the layer's dispatch reducing them in place, or (an array
// of instance pointers) the dispatch gathering the pointers and the records they name.
enum Stage : uint8_t { kCopied = 0, kReduced = 1, kGathered = 2 };

using recording::CaptureDropped;
using recording::CommandCounts;
using recording::KeepOpen;
using recording::Reserve;
using recording::ResolveDestinations;
using recording::RoomForJobs;

// The public functions below, but an allocation failure throws (before anything is recorded into cb: each
// records its commands last); the public ones catch it.
uint32_t CaptureSerializedBlobOrThrow(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                                      VkDeviceAddress address, VkAccelerationStructureKHR src);

}  // namespace

namespace {

// CaptureBuildInputs, but an allocation failure throws (nothing is recorded into cb here: the run's capture point
// records the copies and the dispatch).
bool CaptureBuildInputsOrThrow(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                               uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                               const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                               std::vector<uint32_t>& captured) {
  InjectBadAlloc(FailSite::kCaptureRecord);
  // Kept from call to call on this thread (nothing here calls back into the app): no allocation per call.
  thread_local std::vector<CaptureSource> sources;
  thread_local std::vector<uint32_t> first_source;     // per geometry, and one past the last
  thread_local std::vector<uint8_t> reduced;           // per geometry: how it is captured (Stage)
  thread_local std::vector<CapturedGeometry> planned;  // the info's geometries, before they join the log
  thread_local std::vector<CommandDestination> destinations;
  // The copies and the jobs join the run's (capture_run.h), recorded at its capture point.
  CaptureRun& run = recording.capture_run;
  std::vector<CaptureCopy>& copies = run.copies;
  const std::size_t copies_before = copies.size();
  CommandCounts counts;
  // The layer's dispatch (capture_method reduce, or gathering arrays of instance pointers' records): the run's open
  // job block, made sure at the command's first capture that needs it to have room for all of the command's jobs.
  JobBlock& block = run.block;
  bool block_tried = !ctx.pool.dispatches();
  bool use_block = false;
  bool destinations_logged = false;
  uint32_t first_destination = 0;
  for (uint32_t i = 0; i < info_count; ++i) {
    const VkAccelerationStructureBuildGeometryInfoKHR& info = infos[i];
    if (!NeedsCapture(ctx.mode, info)) continue;
    if (captured.empty()) captured.assign(info_count, 0);
    const VkAccelerationStructureBuildRangeInfoKHR* info_ranges = ranges[i];
    // Motion (VK_NV_ray_tracing_motion_blur): triangles are read at both times; motion instances have other records,
    // not captured yet.
    const bool motion = (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0;
    const bool motion_instances = motion && info.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    if (!info_ranges || (!info.pGeometries && !info.ppGeometries) || motion_instances) {
      counts.NotCaptured(motion_instances ? CaptureSkip::kGeometryNotCaptured : CaptureSkip::kNullInput);
      continue;
    }
    CaptureLog& log = recording.CaptureLogFor(ctx.pool.shared_from_this());
    CapturedInfo entry;
    entry.geometry_count = info.geometryCount;
    entry.element = i;
    if (info_count > 1 && info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
      if (!destinations_logged) {  // once per command, shared by its top-level infos
        ResolveDestinations(ctx.state, info_count, infos, false,
                            [&](uint32_t k) {  // primitiveCount is a range info's first member
                              return std::make_pair(ranges[k] ? &ranges[k][0].primitiveCount : nullptr,
                                                    uint32_t{sizeof(VkAccelerationStructureBuildRangeInfoKHR)});
                            },
                            destinations);
        first_destination = log.AddDestinations(destinations.data(), info_count);
        destinations_logged = true;
      }
      entry.first_destination = first_destination;
      entry.destination_count = info_count;
    }
    planned.assign(info.geometryCount, CapturedGeometry{});
    sources.clear();
    first_source.assign(1, 0);
    CaptureSkip why = CaptureSkip::kNullInput;  // the first reason that stopped the info, once it is not complete
    for (uint32_t j = 0; j < info.geometryCount && entry.complete; ++j) {
      const VkAccelerationStructureGeometryKHR* g = info.pGeometries ? &info.pGeometries[j] : info.ppGeometries[j];
      entry.complete = g && PlanCapturedGeometry(*g, info_ranges[j], false, &planned[j], sources, &why, motion);
      first_source.push_back(static_cast<uint32_t>(sources.size()));
    }
    if (!block_tried) {
      // Where the capture copies, only an array of instance pointers needs the dispatch (its records' stage).
      bool wanted = ctx.pool.reduces();
      for (std::size_t j = 0; j + 1 < first_source.size() && !wanted; ++j) wanted = Gatherable(planned[j]);
      if (wanted) {  // room for a job per geometry of the infos captured from here on
        uint32_t jobs = 0;
        for (uint32_t k = i; k < info_count; ++k) {
          if (NeedsCapture(ctx.mode, infos[k])) jobs += std::min(infos[k].geometryCount, kReduceMaxJobsPerDispatch + 1);
          jobs = std::min(jobs, kReduceMaxJobsPerDispatch + 1);
        }
        use_block = RoomForJobs(ctx, run, log, jobs);
        block_tried = true;
      }
    }
    // What the info costs: each geometry's bytes, or what the dispatch writes for it and its job.
    reduced.assign(first_source.size() - 1, kCopied);
    VkDeviceSize total = 0;
    for (std::size_t j = 0; j < reduced.size(); ++j) {
      if (use_block && ctx.pool.gathers() && Gatherable(planned[j]) && first_source[j + 1] == first_source[j] + 1) {
        reduced[j] = kGathered;
        total = SaturatingAddBytes(total, GatheredCost(planned[j]));
        continue;
      }
      reduced[j] = use_block && ctx.pool.reduces() && Reducible(planned[j]) ? kReduced : kCopied;
      if (reduced[j] == kReduced) {
        const ReducedSources of = SourcesOf(planned[j], sources.data() + first_source[j],
                                            sources.data() + first_source[j + 1]);
        total = SaturatingAddBytes(total, ReducedCost(planned[j], of));
        continue;
      }
      for (uint32_t k = first_source[j]; k < first_source[j + 1]; ++k) {
        total = SaturatingAddBytes(total, sources[k].size);
      }
    }
    if (entry.complete && SaturatingAddBytes(log.bytes_captured, total) > ctx.budget_bytes) {
      entry.complete = false;
      why = CaptureSkip::kOverBudget;
    }
    const std::size_t first_copy = copies.size();
    const uint32_t first_job = block.dispatch.jobs;
    for (std::size_t j = 0; j < reduced.size() && entry.complete; ++j) {
      if (reduced[j] == kGathered) {
        entry.complete = GatherInstancePointers(ctx.state, log, planned[j], sources[first_source[j]], block, &why);
        continue;
      }
      if (reduced[j] == kReduced) {
        entry.complete = ReduceGeometry(
            ctx.state, log, planned[j],
            SourcesOf(planned[j], sources.data() + first_source[j], sources.data() + first_source[j + 1]), block,
            &why);
        continue;
      }
      for (uint32_t k = first_source[j]; k < first_source[j + 1]; ++k) {
        const CaptureSource& s = sources[k];
        CaptureSkip missing = CaptureSkip::kUnknownAddress;
        const std::optional<CopySource> from = CaptureCopySource(ctx.state, ctx.aliases, s.address, s.size, &missing);
        if (!from && s.optional) continue;
        if (!from || !Reserve(ctx, log, s.size, s.into)) {
          why = from ? CaptureSkip::kCaptureMemoryFailed : missing;
          entry.complete = false;
          break;
        }
        copies.push_back(CaptureCopy{from->buffer, log.BufferOf(*s.into),
                                     VkBufferCopy{from->offset, s.into->offset, s.size}, from->aliased,
                                     static_cast<uint32_t>(log.infos.size())});
      }
    }
    if (!entry.complete) {
      copies.resize(first_copy);
      block.dispatch.jobs = first_job;
      counts.NotCaptured(why);
    } else {
      ++counts.captured;
      counts.bytes += total;
    }
    captured[i] = log.AddInfo(entry, planned.data(), nullptr, total);
  }
  KeepOpen(ctx, cb, recording, copies_before);
  counts.AddTo(ctx.counters);
  return !captured.empty();
}

}  // namespace

bool CaptureBuildInputs(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                        uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                        const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                        std::vector<uint32_t>& captured) {
  captured.clear();
  if (!infos || !ranges || !ctx.next.CmdCopyBuffer || !ctx.next.CmdPipelineBarrier) return false;
  try {
    return CaptureBuildInputsOrThrow(ctx, cb, recording, info_count, infos, ranges, captured);
  } catch (const std::bad_alloc&) {
    // What the run planned before the failure is still recorded at its capture point (nobody reads it).
    KeepOpen(ctx, cb, recording, 1);
    uint64_t needing = 0;
    for (uint32_t i = 0; i < info_count; ++i) needing += NeedsCapture(ctx.mode, infos[i]);
    return CaptureDropped(ctx, needing, captured);
  }
}


uint32_t CaptureSerializedBlob(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                               VkDeviceAddress address, VkAccelerationStructureKHR src) {
  if (ctx.mode == kCaptureOff || address == 0 || !ctx.next.CmdCopyBuffer || !ctx.next.CmdPipelineBarrier) return 0;
  try {
    return CaptureSerializedBlobOrThrow(ctx, cb, recording, address, src);
  } catch (const std::bad_alloc&) {
    // Nothing recorded (the copy is recorded last, after which nothing allocates): the blob is not captured.
    std::vector<uint32_t> none;
    CaptureDropped(ctx, 0, none);
    ctx.counters.blobs_not_captured.fetch_add(1, std::memory_order_relaxed);
    return 0;
  }
}

namespace {

uint32_t CaptureSerializedBlobOrThrow(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                                      VkDeviceAddress address, VkAccelerationStructureKHR src) {
  InjectBadAlloc(FailSite::kCaptureRecord);
  // The header (two UUIDs, then the serialized size, the deserialized size and the handle count): less than it
  // can never be hashed.
  constexpr VkDeviceSize kHeaderBytes = 2 * VK_UUID_SIZE + 3 * sizeof(uint64_t);
  // The bound buffer holding `address` that reaches furthest past it, read through what the layer may name there
  // (capture_buffers.h). Inline hits: no allocation.
  AddressHits hits;
  ctx.state.buffer_addresses.FindContaining(address, hits);
  std::optional<CopySource> from;
  VkDeviceSize capacity = 0;
  for (const AddressHit& hit : hits) {
    const VkDeviceSize remaining = hit.base + hit.size - address;
    if (remaining <= capacity) continue;
    std::optional<std::shared_ptr<const BufferState>> b = ctx.state.buffers.find(hit.buffer);
    if (!b || !*b || !(*b)->bound || (*b)->memory == VK_NULL_HANDLE) continue;
    const std::optional<CopySource> source =
        CopySourceIn(ctx.state, ctx.aliases, **b, hit.base, hit.size, address, kHeaderBytes);
    if (!source || source->bytes_left <= capacity) continue;
    from = source;
    capacity = source->bytes_left;
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
  if (bytes < kHeaderBytes || !Reserve(ctx, log, bytes, &into)) {
    ctx.counters.blobs_not_captured.fetch_add(1, std::memory_order_relaxed);
    return 0;
  }
  // One copy: a single-element array of the thread's (no allocation per call), after the open run's captures (a
  // serialization ends the run: blobs are rare next to builds).
  thread_local std::vector<CaptureCopy> copies;
  copies.clear();
  copies.push_back(CaptureCopy{from->buffer, log.BufferOf(into), VkBufferCopy{from->offset, into.offset, bytes},
                               from->aliased, UINT32_MAX});
  const uint32_t blob = log.AddBlob(into);  // before the copy is recorded: it may allocate
  static const std::vector<CaptureDispatch> kNoDispatch;
  RecordCaptureRun(ctx, cb, recording);
  RecordCaptures(ctx, cb, copies, kNoDispatch, VK_NULL_HANDLE);
  ctx.counters.capture_points.fetch_add(1, std::memory_order_relaxed);
  ctx.counters.blobs_captured.fetch_add(1, std::memory_order_relaxed);
  ctx.counters.bytes_captured.fetch_add(bytes, std::memory_order_relaxed);
  return blob;
}

}  // namespace

}  // namespace asval
