// Pre-record of vkCmdBuildAccelerationStructuresIndirectKHR (capture_recorder.h, issue 28): the copies of each info's
// range infos (the first stage), and for the infos `capture` names the jobs of the layer's dispatch that read the
// geometry those range infos select (the second stage, docs/capture.md "Indirect builds"); the command's
// destinations for the rules about its top-level infos' instances.
#include <algorithm>
#include <cstring>
#include <new>
#include <utility>
#include <vector>

#include "capture_buffers.h"
#include "capture_plan.h"
#include "capture_recorder.h"
#include "capture_recording.h"
#include "capture_reduce_jobs.h"
#include "failure_injection.h"

namespace asval {

namespace {

using recording::CaptureDropped;
using recording::CommandCounts;
using recording::KeepOpen;
using recording::Reserve;
using recording::ResolveDestinations;
using recording::RoomForJobs;

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
  const VkAccelerationStructureGeometryKHR* g = info.pGeometries    ? &info.pGeometries[j]
                                                : info.ppGeometries ? info.ppGeometries[j]
                                                                    : nullptr;
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

bool CaptureIndirectRanges(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                           uint32_t info_count,
                           const VkAccelerationStructureBuildGeometryInfoKHR* infos, const VkDeviceAddress* addresses,
                           const uint32_t* strides, const uint32_t* const* max_primitive_counts,
                           std::vector<uint32_t>& captured) {
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
        entry.indirect_geometry =
            ReduceIndirectGeometries(ctx, run, log, infos[i], addresses[i], strides[i], max_primitive_counts[i],
                                     planned, &geometry_bytes, &geometry_why);
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
    KeepOpen(ctx, cb, recording, copies_before);
    counts.AddTo(ctx.counters);
    return !captured.empty();
  } catch (const std::bad_alloc&) {
    return CaptureDropped(ctx, needing, captured);
  }
}

}  // namespace asval
