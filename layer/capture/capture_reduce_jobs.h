#pragma once
// The jobs of the capture reduced on the device (capture_method, capture_reducer.h): which geometries a build
// command's dispatch can read in place, their jobs written into the recording's capture log, and the one dispatch
// that runs them. Called by the recorder (capture_recorder.cpp) while it records a build's captures.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "capture_log.h"
#include "capture_plan.h"
#include "capture_reducer.h"
#include "capture_run.h"
#include "device_state.h"

namespace asval {

// Room for `jobs` more jobs in `block` (capture_run.h) and the pipeline: the block is taken anew in the recording's
// log, for at least `jobs` and, where the log has room, for `wanted` (a run's later commands then add theirs to the
// same dispatch). False (the captures are then copied) when the pipeline is missing or the log has no room; the
// block's jobs so far must have been moved out first (its dispatch recorded or kept by the run).
bool AcquireJobs(JobBlock& block, CaptureLog& log, uint32_t jobs, uint32_t wanted, VkPipeline pipeline);
void AddJob(JobBlock& block, const ReduceJob& job);

// Whether geometry g's bytes (its `data`) can be reduced on the device instead of copied: triangles, AABBs, and
// instances given as an array of records, with strides the shader's 32-bit arithmetic holds.
bool Reducible(const CapturedGeometry& g);

// The second stage of an array of instance pointers' capture (where the pool gathers, CaptureGathers): the
// command's dispatch reads the pointers where the build reads them and copies them, and the 64-byte record each
// followed one names (FollowedInstancePointer), into the log (CapturedGeometry::pointers, then ::data: GatheredBytes).
// Gatherable: g is such an array, and the shader's 32-bit arithmetic holds its bytes; GatheredCost: what it costs
// the recording's budget (the bytes and the job). GatherInstancePointers: false when the pointers cannot be read in
// place (no bound buffer holds them: *why kUnknownAddress) or there is no room (kCaptureMemoryFailed): the info is
// then not captured.
bool Gatherable(const CapturedGeometry& g);
inline VkDeviceSize GatheredCost(const CapturedGeometry& g) {
  return GatheredBytes(g.range.primitiveCount) + sizeof(ReduceJob);
}
// `indirect_range`: an indirect build's geometry (ReduceJob::kIndirect), its range info's device address; g is then
// planned for a range of offset 0 and the most primitives, and only where its bytes start must lie in a bound buffer
// (how far the build reads from there is known on the device alone).
bool GatherInstancePointers(const DeviceState& state, CaptureLog& log, CapturedGeometry& g,
                            const CaptureSource& pointers, JobBlock& block, CaptureSkip* why,
                            VkDeviceAddress indirect_range = 0);

// Geometry g's sources among its planned ones [first, last): its data, and for triangles its indices and its
// transform (each null when the plan has none).
struct ReducedSources {
  const CaptureSource* data = nullptr;
  const CaptureSource* indices = nullptr;
  const CaptureSource* transform = nullptr;
};
ReducedSources SourcesOf(const CapturedGeometry& g, const CaptureSource* first, const CaptureSource* last);
// What reducing g costs the recording's budget: the results the dispatch writes, and its job.
VkDeviceSize ReducedCost(const CapturedGeometry& g, const ReducedSources& sources);

// Geometry g's sources read in place by the command's dispatch: its results reserved in the log (the indices and
// transform among them, where the builder's views find them), its job added to `block`. False when a source cannot
// be read (no bound buffer holds it: *why kUnknownAddress; the transform is then left out instead) or there is no
// room (kCaptureMemoryFailed): the info is then not captured.
// `indirect_range` as for GatherInstancePointers.
bool ReduceGeometry(const DeviceState& state, CaptureLog& log, CapturedGeometry& g, const ReducedSources& sources,
                    JobBlock& block, CaptureSkip* why, VkDeviceAddress indirect_range = 0);

}  // namespace asval
