#pragma once
// Pre-record of a device build (execution-time capture, issue 12): decides which infos' inputs a rule needs at
// execution time and plans their capture into the recording's capture log: one copy per input range or, where the
// capture reduces on the device (capture_method, capture_reducer.h), one job of the layer's dispatch per geometry it
// can read in place (capture_reduce_jobs.h). The copies and the dispatch join the recording's open run of build
// commands (capture_run.h) and are recorded into the command buffer where the run ends, after a wait on the run's
// start event (or a barrier) and before a barrier (capture_run_end.h): N build commands in a row cost one capture
// point.
//
// Captured (setting `capture`): with `updates` (the default), bottom-level builds with ALLOW_UPDATE (a later
// update's source: their activity record), updates, and every top-level build (its instance references); with
// `all`, every bottom-level build too. Arrays of instance pointers: the pointers, then the records they point to,
// gathered by the layer's dispatch where the pool gathers (CaptureGathers; elsewhere the pointers only, the records
// unknown). Motion builds' triangles are read at both times (capture_plan.h). Not captured yet (their rules skipped and
// counted): motion instances, vertex formats the builder does not decode.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <vector>

#include "capture_plan.h"
#include "capture_pool.h"
#include "device_state.h"
#include "layer_settings.h"
#include "memory_aliases.h"
#include "vk_dispatch_table.h"

namespace asval {

struct CaptureContext {
  const DeviceState& state;
  const DeviceDispatchTable& next;
  CapturePool& pool;
  MemoryAliases& aliases;  // what the copies read through (memory_aliases.h)
  CaptureMode mode;
  VkDeviceSize budget_bytes;  // per recording
  CaptureCounters& counters;
};

// Whether a build info needs its inputs captured (cheap: the hot path of builds that need none).
inline bool NeedsCapture(CaptureMode mode, const VkAccelerationStructureBuildGeometryInfoKHR& info) {
  if (mode == kCaptureOff) return false;
  // Top level: every build (its instance references are checked), and its updates (instance activity).
  if (info.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR) return true;
  if (info.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) return false;
  return mode == kCaptureAll || ActivityNeededForUpdates(info);
}

// vkCmdBuildAccelerationStructuresKHR: plans the captures of the infos that need them into `recording`'s run and
// writes, per info, its index in recording.capture_log->infos plus one, or 0, into
// `captured` (resized to info_count). False when nothing was captured (captured is then left empty).
bool CaptureBuildInputs(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                        uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                        const VkAccelerationStructureBuildRangeInfoKHR* const* ranges, std::vector<uint32_t>& captured);

// vkCmdBuildAccelerationStructuresIndirectKHR (capture_indirect.cpp): plans the copies of every info's range infos
// (read by the device from pIndirectDeviceAddresses[i], pIndirectStrides[i] apart), keeping ppMaxPrimitiveCounts[i]
// with them, so that the counts can be checked once the submission completes; and, for the infos `capture` names,
// where the pool dispatches (CaptureGathers), the second stage: the geometry those range infos select, read by the
// layer's dispatch (docs/capture.md "Indirect builds"). `captured` as for CaptureBuildInputs.
bool CaptureIndirectRanges(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                           uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                           const VkDeviceAddress* addresses, const uint32_t* strides,
                           const uint32_t* const* max_primitive_counts, std::vector<uint32_t>& captured);

// Device serialization (issue 12): the serialized bytes at `address` copied into the recording's capture log,
// between the same two barriers as the builds' captures (after the open run's, which ends here), so that a deserialization can be verified by content.
// vkCmdCopyAccelerationStructureToMemoryKHR: called AFTER the app's serialization was recorded (the copy captures
// what it wrote; the first barrier makes its write visible), with `src` the serialized structure.
// vkCmdCopyMemoryToAccelerationStructureKHR: called BEFORE the app's deserialization (what it will read), with src
// VK_NULL_HANDLE. How many bytes: the blob's size is in its header on the device, unknown here; the copy takes the
// serialization size when the app read it back for src's current contents (else the size of the last blob the
// layer saw serialized at `address`), at most what the app's buffer holding `address` has left, and at most
// what the recording's budget has left (a copy that turns out shorter than the header's size leaves the bytes
// unknown, never guessed). Read through the layer's buffer over the memory (capture_buffers.h); in a dedicated
// allocation only from a buffer created with TRANSFER_SRC (BufferState::capture_source). Returns the blob's index in recording.capture_log->blobs plus one; 0 when nothing was captured.
uint32_t CaptureSerializedBlob(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording,
                               VkDeviceAddress address, VkAccelerationStructureKHR src);

}  // namespace asval
