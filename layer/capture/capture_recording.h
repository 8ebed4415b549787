#pragma once
// What the two build recorders share (capture_recorder.cpp: direct builds; capture_indirect.cpp: indirect builds):
// keeping the recording's run open, room in its slabs and its job block, the counters a command adds, an
// allocation failure's accounting, and the command's destinations for the rules about instances. Internal to
// layer/capture.
#include <vulkan/vulkan.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "capture_recorder.h"
#include "capture_run.h"
#include "history.h"
#include "structure_memory.h"

namespace asval {
namespace recording {

// The run's captures planned by this command are in the run: it is open until its capture point
// (capture_run_end.h). The run's first copy notes the aliases' epoch (a source destroyed before the capture point
// is left out there). A run that opens here sets its start event in cb, before the command that opened it (where
// the recording may not use one, or none can be had, its capture point waits with a barrier).
void KeepOpen(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording, std::size_t copies_before);

// Room in the recording's slabs; false only when the pool could not give a slab (the device's memory, or the
// layer's vkCreateBuffer / vkAllocateMemory / vkMapMemory, failed): counted as a capture memory failure.
bool Reserve(const CaptureContext& ctx, CaptureLog& log, VkDeviceSize size, CapturedBytes* where);

// An allocation of the capture's own failed while it recorded a command's copies, before any was recorded: the
// command captures nothing (its rules skipped and counted as for bytes not captured), and `needing` infos that
// needed a capture are counted as not captured (kAllocationFailed).
bool CaptureDropped(const CaptureContext& ctx, uint64_t needing, std::vector<uint32_t>& captured);

// Room in the run's open job block for `jobs` more jobs of the layer's dispatch: the block kept when it has room,
// else a new one, larger each time a run outgrows one (a long run takes few dispatches). False when the pipeline
// or the log's memory is missing (the captures are then copied, or not made).
bool RoomForJobs(const CaptureContext& ctx, CaptureRun& run, CaptureLog& log, uint32_t jobs);

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

}  // namespace recording
}  // namespace asval
