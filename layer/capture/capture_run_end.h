#pragma once
// The capture point of a run of build commands (capture_run.h): what the builds recorded since the last one
// planned, recorded into the app's command buffer in one go, between two barriers. Called by the hooks of the
// commands that end a run (layer/loader/run_end_hooks.cpp, vkEndCommandBuffer, vkCmdExecuteCommands) before their
// downcall, and by the capture of a serialized blob before its own copy.
//
//   barrier  ALL_COMMANDS / MEMORY_WRITE -> TRANSFER | COMPUTE_SHADER / TRANSFER_READ | SHADER_READ
//   the run's copies, then its reducing dispatches (the app's compute pipeline bound again after them)
//   barrier  TRANSFER | COMPUTE_SHADER / TRANSFER_WRITE | SHADER_WRITE
//            -> HOST | ALL_COMMANDS / HOST_READ | TRANSFER_WRITE | SHADER_WRITE
//
// The first barrier makes every earlier write, those the builds read included, visible to the captures; the builds
// of the run are earlier commands too, so the captures run after them and read the same bytes: nothing between the
// builds and this point writes their inputs in a valid program (such a write would need a barrier, an event or a
// render pass after the build that reads them, and each of those ends the run here first). The second makes the
// captured bytes visible to the host, and keeps every later command (a write of the inputs included) behind the
// reads.
#include <vulkan/vulkan.h>

#include <vector>

#include "capture_recorder.h"

namespace asval {

// Records recording's open run into cb and closes it; nothing when no run is open. A copy whose source buffer
// was destroyed since the build planned it (the app freed the memory while recording: MemoryAliases::Epoch) is
// left out, and its info counted as not captured (kUnknownAddress) instead.
void RecordCaptureRun(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording);

// The barriers above around `copies` and `dispatches` (a serialized blob's capture records its one copy so).
void RecordCaptures(const CaptureContext& ctx, VkCommandBuffer cb, const std::vector<CaptureCopy>& copies,
                    const std::vector<CaptureDispatch>& dispatches, VkPipeline app_pipeline);

}  // namespace asval
