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

// The run's captures planned by this command are in the run: it is open until its capture point
// (capture_run_end.h). The run's first copy notes the aliases' epoch (a source destroyed before the capture point
// is left out there).
void KeepOpen(const CaptureContext& ctx, CaptureRun& run, std::size_t copies_before) {
  if (copies_before == 0 && !run.copies.empty()) run.aliases_epoch = ctx.aliases.Epoch();
  if (!run.Empty()) run.Open(ctx.state.command_buffers.open_capture_runs());
}

// Room in the recording's slabs; false only when the pool could not give a slab (the device's memory, or the
// layer's vkCreateBuffer / vkAllocateMemory / vkMapMemory, failed): counted as a capture memory failure.
bool Reserve(const CaptureContext& ctx, CaptureLog& log, VkDeviceSize size, CapturedBytes* where) {
  if (log.Reserve(size, where)) return true;
  ctx.counters.failures.capture_memory_failures.fetch_add(1, std::memory_order_relaxed);
  return false;
}

// An allocation of the capture's own failed while it recorded a command's copies, before any was recorded: the
// command captures nothing (its rules skipped and counted as for bytes not captured), and `needing` infos that
// needed a capture are counted as not captured (kAllocationFailed).
bool CaptureDropped(const CaptureContext& ctx, uint64_t needing, std::vector<uint32_t>& captured) {
  captured.clear();
  FailureCounters& failures = ctx.counters.failures;
  failures.allocation_failures.fetch_add(1, std::memory_order_relaxed);
  failures.capture_commands_dropped.fetch_add(1, std::memory_order_relaxed);
  ctx.counters.NotCaptured(CaptureSkip::kAllocationFailed, needing);
  return false;
}

// The public functions below, but an allocation failure throws (before anything is recorded into cb: each
// records its commands last); the public ones catch it.
uint32_t CaptureSerializedBlobOrThrow(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                                      VkDeviceAddress address, VkAccelerationStructureKHR src);

// What a command's captures add to the counters, added once its copies are recorded (a command dropped by an
// allocation failure adds nothing but its infos not captured).
struct CommandCounts {
  uint64_t captured = 0, bytes = 0;
  std::array<uint64_t, kCaptureSkipCount> not_captured{};  // per reason
  void NotCaptured(CaptureSkip why) { ++not_captured[SkipIndex(why)]; }
  void AddTo(CaptureCounters& counters) const {
    counters.infos_captured.fetch_add(captured, std::memory_order_relaxed);
    counters.bytes_captured.fetch_add(bytes, std::memory_order_relaxed);
    for (std::size_t r = 0; r < kCaptureSkipCount; ++r) {
      counters.NotCaptured(static_cast<CaptureSkip>(r), not_captured[r]);
    }
  }
};

// The destinations of a build command of several infos, for the rules about its top-level infos' instances and
// its other destinations (None-03407, dstAccelerationStructure-03706), judged once the instances are captured.
// The bytes each build writes are its accelerationStructureSize, as the size cache holds it: the command's
// validation has just looked it up (or asked the driver). A size or memory not known leaves the span unknown.
// counts_of(i): pInfos[i]'s primitive counts and the bytes from one to the next (null: not given). An indirect
// command's are its ppMaxPrimitiveCounts: the bytes it writes for them are the bytes it writes when the range infos
// the device reads hold those very counts (judged at completion: ExecutedAccess, capture_log.h).
template <typename CountsOf>
void ResolveDestinations(const DeviceState& state, uint32_t info_count,
                         const VkAccelerationStructureBuildGeometryInfoKHR* infos, bool indirect, CountsOf counts_of,
                         std::vector<CommandDestination>& out) {
  out.assign(info_count, CommandDestination{});
  for (uint32_t i = 0; i < info_count; ++i) {
    CommandDestination& d = out[i];
    d.handle = infos[i].dstAccelerationStructure;
    d.element = i;
    d.indirect = indirect;
    const std::optional<StructureMemory> memory = MemoryOfStructure(state, d.handle);
    if (!memory) continue;
    d.address = memory->structure->device_address;
    const auto [counts, stride] = counts_of(i);
    if (!counts && infos[i].geometryCount != 0) continue;
    if (!GeometryCountWithinLimit(infos[i], state.properties.acceleration_structure.maxGeometryCount)) continue;
    BuildSignature signature;
    signature.info = &infos[i];
    signature.counts = counts;
    signature.count_stride = stride;
    BuildSizes sizes;
    if (infos[i].geometryCount != 0 && !state.build_sizes.Find(signature, &sizes)) continue;
    if (std::optional<MemorySpan> span = memory->Span(sizes.acceleration_structure_size)) d.accessed = *span;
  }
}

// Where each destination's range infos were logged (ResolveDestinations of an indirect command): infos [0, through)
// of the command so far, `captured` holding each one's log index plus one (0: not logged).
void NoteCountsInfos(CaptureLog& log, uint32_t first_destination, uint32_t through,
                     const std::vector<uint32_t>& captured, const VkAccelerationStructureBuildGeometryInfoKHR* infos) {
  for (uint32_t k = 0; k < through && k < captured.size(); ++k) {
    CommandDestination& d = log.destinations[first_destination + k];
    if (captured[k] != 0) {
      d.counts_info = captured[k] - 1;
    } else if (infos[k].geometryCount != 0) {
      d.accessed = MemorySpan{};  // its counts are not known: neither are the bytes it writes
    }
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

// Room in the run's open job block for `jobs` more jobs of the layer's dispatch: the block kept when it has room,
// else a new one, larger each time a run outgrows one (a long run takes few dispatches). False when the pipeline
// or the log's memory is missing (the captures are then copied, or not made).
bool RoomForJobs(const CaptureContext& ctx, CaptureRun& run, CaptureLog& log, uint32_t jobs) {
  JobBlock& block = run.block;
  const VkPipeline pipeline = ctx.pool.ReducePipeline();
  if (pipeline == VK_NULL_HANDLE && !ctx.counters.failures.reduce_pipeline_failed.exchange(true)) {
    ctx.counters.failures.inserted_failures.fetch_add(1, std::memory_order_relaxed);  // once: made once
  }
  if (block.Room() >= jobs && block.dispatch.pipeline == pipeline) return true;
  if (block.dispatch.jobs != 0) run.dispatches.push_back(block.dispatch);
  return AcquireJobs(block, log, jobs, std::max<uint32_t>(64, 2 * block.capacity), pipeline);
}

// The second stage of an indirect build's capture (issue 28): info i's geometries read by the layer's dispatch
// where the build read them, at the offsets and for the count of the range infos the device reads (known on the
// device alone: the dispatch reads each range info first, reduce_inputs.comp), into results sized for the
// ppMaxPrimitiveCounts[i] the build may read at most. Only where the pool dispatches for arrays of instance pointers
// too (CaptureGathers: no copy recorded beforehand can name these bytes); reduced whatever capture_method says.
// False, with *why, when a geometry cannot be read so (the info's activity and instances are then unknown).
// *bytes: what the results cost the recording's budget.
bool ReduceIndirectGeometries(const CaptureContext& ctx, CaptureRun& run, CaptureLog& log,
                              const VkAccelerationStructureBuildGeometryInfoKHR& info, VkDeviceAddress ranges,
                              uint32_t stride, const uint32_t* max_counts, std::vector<CapturedGeometry>& planned,
                              VkDeviceSize* bytes, CaptureSkip* why) {
  *why = CaptureSkip::kGeometryNotCaptured;
  if (!ctx.pool.gathers() || (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0) return false;
  // Kept from call to call on this thread (nothing here calls back into the app): no allocation per call.
  thread_local std::vector<CaptureSource> sources;
  const uint32_t n = info.geometryCount;
  VkDeviceSize total = 0;
  for (uint32_t j = 0; j < n; ++j) {
    const VkAccelerationStructureGeometryKHR* g = info.pGeometries ? &info.pGeometries[j] : info.ppGeometries[j];
    // Planned as a range of offset 0 and the most primitives: the dispatch applies the range info's own.
    VkAccelerationStructureBuildRangeInfoKHR most{};
    most.primitiveCount = max_counts[j];
    sources.clear();
    CapturedGeometry& p = planned[j];
    if (!g || !PlanCapturedGeometry(*g, most, false, &p, sources, why)) return false;
    KeepRangeFacts(info, j, &p);
    if (most.primitiveCount == 0) continue;
    const bool gathered = Gatherable(p) && sources.size() == 1;
    if (!gathered && !Reducible(p)) return false;
    const CaptureSource* const first = sources.data();
    const CaptureSource* const last = first + sources.size();
    total = SaturatingAddBytes(total, gathered ? GatheredCost(p) : ReducedCost(p, SourcesOf(p, first, last)));
  }
  if (SaturatingAddBytes(log.bytes_captured, total) > ctx.budget_bytes) {
    *why = CaptureSkip::kOverBudget;
    return false;
  }
  if (!RoomForJobs(ctx, run, log, std::min(n, kReduceMaxJobsPerDispatch + 1))) {
    *why = CaptureSkip::kCaptureMemoryFailed;
    return false;
  }
  const uint32_t first_job = run.block.dispatch.jobs;
  for (uint32_t j = 0; j < n; ++j) {
    if (max_counts[j] == 0) continue;
    const VkAccelerationStructureGeometryKHR* g = info.pGeometries ? &info.pGeometries[j] : info.ppGeometries[j];
    VkAccelerationStructureBuildRangeInfoKHR most{};
    most.primitiveCount = max_counts[j];
    sources.clear();
    CapturedGeometry& p = planned[j];
    PlanCapturedGeometry(*g, most, false, &p, sources, why);  // as above: the sources again
    KeepRangeFacts(info, j, &p);
    const VkDeviceAddress range = ranges + VkDeviceSize{stride} * j;
    const CaptureSource* const first = sources.data();
    const CaptureSource* const last = first + sources.size();
    const bool ok = Gatherable(p) && sources.size() == 1
                        ? GatherInstancePointers(ctx.state, log, p, sources[0], run.block, why, range)
                        : ReduceGeometry(ctx.state, log, p, SourcesOf(p, first, last), run.block, why, range);
    if (!ok) {
      run.block.dispatch.jobs = first_job;
      return false;
    }
  }
  *bytes = total;
  return true;
}

}  // namespace

bool CaptureIndirectRanges(const CaptureContext& ctx, CommandBufferState& recording,
                           uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                           const VkDeviceAddress* addresses, const uint32_t* strides,
                           const uint32_t* const* max_primitive_counts, std::vector<uint32_t>& captured) {
  captured.clear();
  if (ctx.mode == kCaptureOff || !infos || !addresses || !strides || !max_primitive_counts || !ctx.next.CmdCopyBuffer ||
      !ctx.next.CmdPipelineBarrier) {
    return false;
  }
  uint64_t needing = 0;
  for (uint32_t i = 0; i < info_count; ++i) {
    needing += infos[i].geometryCount != 0 && max_primitive_counts[i] && addresses[i] != 0;
  }
  try {
    InjectBadAlloc(FailSite::kCaptureRecord);
    // No geometry data (only the range infos are captured): the facts their rules need. Kept from call to call on
    // this thread (nothing here calls back into the app): no allocation per call.
    thread_local std::vector<CapturedGeometry> planned;
    thread_local std::vector<CommandDestination> destinations;
    bool destinations_logged = false;
    uint32_t first_destination = 0;
    CaptureRun& run = recording.capture_run;
    const std::size_t copies_before = run.copies.size();
    CommandCounts counts;
    for (uint32_t i = 0; i < info_count; ++i) {
      const uint32_t n = infos[i].geometryCount;
      if (n == 0 || !max_primitive_counts[i] || addresses[i] == 0) continue;
      if (captured.empty()) captured.assign(info_count, 0);
      CaptureLog& log = recording.CaptureLogFor(ctx.pool.shared_from_this());
      CapturedInfo entry;
      entry.indirect = true;
      entry.element = i;
      entry.geometry_count = n;
      entry.indirect_stride = strides[i];
      const VkDeviceSize bytes =
          SaturatingAddBytes(SaturatingMulBytes(strides[i], n - 1), sizeof(VkAccelerationStructureBuildRangeInfoKHR));
      const bool within_budget = SaturatingAddBytes(log.bytes_captured, bytes) <= ctx.budget_bytes;
      CaptureSkip why = CaptureSkip::kOverBudget;
      const std::optional<CopySource> from =
          within_budget ? CaptureCopySource(ctx.state, ctx.aliases, addresses[i], bytes, &why) : std::nullopt;
      const bool reserved = from && Reserve(ctx, log, bytes, &entry.ranges);
      if (from && !reserved) why = CaptureSkip::kCaptureMemoryFailed;
      if (reserved) {
        run.copies.push_back(CaptureCopy{from->buffer, log.BufferOf(entry.ranges),
                                         VkBufferCopy{from->offset, entry.ranges.offset, bytes}, from->aliased,
                                         static_cast<uint32_t>(log.infos.size())});
        ++counts.captured;
        counts.bytes += bytes;
      } else {
        entry.complete = false;
        counts.NotCaptured(why);
      }
      planned.assign(n, CapturedGeometry{});
      for (uint32_t j = 0; j < n; ++j) KeepRangeFacts(infos[i], j, &planned[j]);
      VkDeviceSize geometry_bytes = 0;
      if (reserved && NeedsCapture(ctx.mode, infos[i]) && (infos[i].pGeometries || infos[i].ppGeometries)) {
        CaptureSkip geometry_why = CaptureSkip::kGeometryNotCaptured;
        entry.indirect_geometry = ReduceIndirectGeometries(ctx, run, log, infos[i], addresses[i], strides[i],
                                                           max_primitive_counts[i], planned, &geometry_bytes,
                                                           &geometry_why);
        if (!entry.indirect_geometry) {
          counts.NotCaptured(geometry_why);
          planned.assign(n, CapturedGeometry{});
          for (uint32_t j = 0; j < n; ++j) KeepRangeFacts(infos[i], j, &planned[j]);
          geometry_bytes = 0;
        } else if (info_count > 1 && infos[i].type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) {
          if (!destinations_logged) {  // once per command, shared by its top-level infos
            ResolveDestinations(
                ctx.state, info_count, infos, true,
                [&](uint32_t k) { return std::make_pair(max_primitive_counts[k], uint32_t{sizeof(uint32_t)}); },
                destinations);
            first_destination = log.AddDestinations(destinations.data(), info_count);
            destinations_logged = true;
          }
          entry.first_destination = first_destination;
          entry.destination_count = info_count;
        }
        counts.bytes += geometry_bytes;
      }
      captured[i] =
          log.AddInfo(entry, planned.data(), max_primitive_counts[i], SaturatingAddBytes(bytes, geometry_bytes));
    }
    if (destinations_logged) {  // every info now logged: where each destination's counts are
      NoteCountsInfos(recording.CaptureLogFor(ctx.pool.shared_from_this()), first_destination, info_count, captured,
                      infos);
    }
    KeepOpen(ctx, run, copies_before);
    counts.AddTo(ctx.counters);
    return !captured.empty();
  } catch (const std::bad_alloc&) {
    return CaptureDropped(ctx, needing, captured);
  }
}

namespace {

// CaptureBuildInputs, but an allocation failure throws (nothing is recorded into cb here: the run's capture point
// records the copies and the dispatch).
bool CaptureBuildInputsOrThrow(const CaptureContext& ctx, CommandBufferState& recording,
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
    // Motion instances (VK_NV_ray_tracing_motion_blur) have other records: not captured yet.
    const bool motion = (info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0;
    if (!info_ranges || (!info.pGeometries && !info.ppGeometries) || motion) {
      counts.NotCaptured(motion ? CaptureSkip::kGeometryNotCaptured : CaptureSkip::kNullInput);
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
      entry.complete = g && PlanCapturedGeometry(*g, info_ranges[j], false, &planned[j], sources, &why);
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
  KeepOpen(ctx, run, copies_before);
  counts.AddTo(ctx.counters);
  return !captured.empty();
}

}  // namespace

bool CaptureBuildInputs(const CaptureContext& ctx, CommandBufferState& recording,
                        uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                        const VkAccelerationStructureBuildRangeInfoKHR* const* ranges,
                        std::vector<uint32_t>& captured) {
  captured.clear();
  if (!infos || !ranges || !ctx.next.CmdCopyBuffer || !ctx.next.CmdPipelineBarrier) return false;
  try {
    return CaptureBuildInputsOrThrow(ctx, recording, info_count, infos, ranges, captured);
  } catch (const std::bad_alloc&) {
    // What the run planned before the failure is still recorded at its capture point (nobody reads it).
    KeepOpen(ctx, recording.capture_run, 1);
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
