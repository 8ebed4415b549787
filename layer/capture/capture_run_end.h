#pragma once
// The capture point of a run of build commands (capture_run.h): what the builds recorded since the last one
// planned, recorded into the app's command buffer in one go, between a wait and a barrier. Called by the hooks of
// the commands that end a run (layer/loader/run_end_hooks.cpp, vkEndCommandBuffer, vkCmdExecuteCommands) before
// their downcall, and by the capture of a serialized blob before its own copy.
//
//   (where the run started: vkCmdSetEvent  start_event, ALL_COMMANDS)
//   builds of the run
//   wait     start_event: ALL_COMMANDS / MEMORY_WRITE -> TRANSFER | COMPUTE_SHADER / TRANSFER_READ | SHADER_READ
//            (no start event: a barrier with the same scopes)
//   the run's copies, then its reducing dispatches (the app's compute pipeline bound again after them)
//   barrier  TRANSFER | COMPUTE_SHADER / TRANSFER_WRITE | SHADER_WRITE
//            -> HOST | ALL_COMMANDS / HOST_READ | TRANSFER_WRITE | SHADER_WRITE
//   vkCmdResetEvent  start_event, ALL_COMMANDS
//
// The wait makes every write recorded before the run, those the builds read included, visible to the captures,
// and only those: the captures then run beside the run's builds instead of after them (issue 27: on a GPU a capture
// point that waited for the builds added its whole dispatch to the frame). They read the bytes the builds read:
// builds write only their destinations and scratch, and nothing between the run's start and this point writes
// their inputs in a valid program (such a write would race with a build's read, or need a barrier, an event or a
// render pass before a later build, and each of those ends the run here first). The barrier makes the captured
// bytes visible to the host, and keeps every later command (a write of the inputs included) behind the reads. The
// reset, after everything before it, leaves the event unsignaled for the next execution of the recording (one that
// may overlap another, SIMULTANEOUS_USE, gets no event). A blob's capture has no start event: it must wait for the
// serialization that wrote its bytes.
#include <vulkan/vulkan.h>

#include <vector>

#include "capture_recorder.h"

namespace asval {

// Records recording's open run into cb and closes it; nothing when no run is open. A copy whose source buffer
// was destroyed since the build planned it (the app freed the memory while recording: MemoryAliases::Epoch) is
// left out, and its info counted as not captured (kUnknownAddress) instead.
void RecordCaptureRun(const CaptureContext& ctx, VkCommandBuffer cb, CommandBufferState& recording);

// The stages the start event is set with, and its wait names.
inline constexpr VkPipelineStageFlags kRunStartStages = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;

// The wait (or barrier) and the barrier above around `copies` and `dispatches`, then the start event's reset (a
// serialized blob's capture records its one copy so, with no start event).
void RecordCaptures(const CaptureContext& ctx, VkCommandBuffer cb, const std::vector<CaptureCopy>& copies,
                    const std::vector<CaptureDispatch>& dispatches, VkPipeline app_pipeline,
                    VkEvent start_event = VK_NULL_HANDLE);

}  // namespace asval
