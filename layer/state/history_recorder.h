#pragma once
// Recording side of the build history (the writes; the rules are in layer/checks/update_rules.h):
//   device commands: append operations to the command buffer's recording (applied at submission: submission.h);
//   host commands:   applied when they complete (at once, or when the deferred operation is seen to complete);
//   query results:   serialization sizes read back, attached to the structures' current contents.
// Every function does nothing when DeviceState::history_tracked is false.
#include <vulkan/vulkan.h>

#include "device_state.h"

namespace asval {

// ---- device commands (after the downcall) ----
// The command buffer a thread recorded a build into last, with the command-buffer map's change stamp at that
// time. While the stamp reads the same, no command buffer was allocated or freed since, so the map still holds
// that very CommandBufferState; and it stays alive for the call: the app externally synchronizes the command
// buffer it records into, so it cannot be freed meanwhile. Saves a map lookup and a reference count per build.
struct LastRecordedBuild {
  StampValue stamp;  // of the map it came from (ids are never reused: another device's map never matches)
  VkCommandBuffer cb = VK_NULL_HANDLE;
  CommandBufferState* state = nullptr;  // null: the layer does not know cb
};

// ranges: null for indirect builds (the counts are on the device). last: the calling thread's memo, kept by the
// caller with its other per-thread data (null: a thread_local of the recorder's own). captured: per info, its
// index in the command buffer's capture log plus one (0: not captured), from the capture's pre-record; null when
// the call captured nothing.
void RecordCmdBuild(DeviceState& state, VkCommandBuffer cb, OpCommand command, uint32_t info_count,
                    const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                    const VkAccelerationStructureBuildRangeInfoKHR* const* ranges, LastRecordedBuild* last = nullptr,
                    const uint32_t* captured = nullptr);
void RecordCmdCopy(DeviceState& state, VkCommandBuffer cb, const VkCopyAccelerationStructureInfoKHR& info);
// captured: the serialized bytes' index in the command buffer's capture log plus one (0: not captured), from the
// capture's post-record (serialization) or pre-record (deserialization).
void RecordCmdCopyToMemory(DeviceState& state, VkCommandBuffer cb,
                           const VkCopyAccelerationStructureToMemoryInfoKHR& info, uint32_t captured = 0);
void RecordCmdCopyMemoryTo(DeviceState& state, VkCommandBuffer cb,
                           const VkCopyMemoryToAccelerationStructureInfoKHR& info, uint32_t captured = 0);
void RecordCmdWriteProperties(DeviceState& state, VkCommandBuffer cb, uint32_t count,
                              const VkAccelerationStructureKHR* structures, VkQueryType type, VkQueryPool pool,
                              uint32_t first_query, OpCommand command = OpCommand::kCmdWriteProperties);
// VK_NV_ray_tracing's commands (structures keyed by NvHistoryKey). A command naming a structure whose handle value a
// live KHR structure also has is not recorded (nv_structures.h: shares_key), and counted as unknown state.
void RecordCmdBuildNV(DeviceState& state, VkCommandBuffer cb, const VkAccelerationStructureInfoNV& info, bool update,
                      VkAccelerationStructureNV dst, VkAccelerationStructureNV src);
void RecordCmdCopyNV(DeviceState& state, VkCommandBuffer cb, VkAccelerationStructureNV dst,
                     VkAccelerationStructureNV src, VkCopyAccelerationStructureModeKHR mode);
void RecordCmdWritePropertiesNV(DeviceState& state, VkCommandBuffer cb, uint32_t count,
                                const VkAccelerationStructureNV* structures, VkQueryType type, VkQueryPool pool,
                                uint32_t first_query);
// vkCmdBindPipeline with VK_PIPELINE_BIND_POINT_COMPUTE, where the capture reduces on the device: the pipeline the
// layer binds again after its dispatch (CommandBufferState::compute_pipeline).
void RecordBindComputePipeline(DeviceState& state, VkCommandBuffer cb, VkPipeline pipeline);
// A secondary executed again by one recording of a primary (a SIMULTANEOUS_USE secondary executed twice, or a
// secondary executed by two secondaries that one primary executes): the device writes its capture bytes again
// before the host reads them. So before that execution, what the executions so far wrote is copied into a log of
// their own (CaptureLog::EmptyCopy), and their operations read it there. The copies are recorded into the primary
// by layer/capture (capture_saves.h), which also passes the app's secondaries down in parts around them.
class CaptureSaver {
 public:
  // The app's secondaries before index `next` not passed down yet go down (vkCmdExecuteCommands of that part).
  virtual void PassDown(uint32_t next) = 0;
  // Records into the primary the copy of `from`'s bytes, as the executions so far left them, into `to` (from's
  // EmptyCopy, held by the primary's recording before this is called). False when nothing was recorded.
  virtual bool RecordCopy(const CaptureLog& from, const CaptureLog& to) = 0;

 protected:
  ~CaptureSaver() = default;
};

// vkCmdExecuteCommands: the secondaries' completed recordings join the primary's, in order. With a saver (the
// device captures), a secondary whose captures the primary's recording already reads has them saved first
// (CaptureSaver); the caller then passes down what the saver has not (saver->PassDown(count)).
void RecordExecuteCommands(DeviceState& state, VkCommandBuffer primary, uint32_t count,
                           const VkCommandBuffer* secondaries, CaptureSaver* saver = nullptr);

// ---- host commands: their operations (pure: built before the checks run) ----
// `capture`, `captured`: the inputs captured when the build was called (host_capture.h; null: none): each
// captured info's operation carries its capture, whose activity is recorded when the operations are applied.
// max_geometry_count: the device's limit, as OpBatch::AppendBuilds takes it.
OpBatch HostBuildOps(uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                     const VkAccelerationStructureBuildRangeInfoKHR* const* ranges, CaptureLog* capture = nullptr,
                     const uint32_t* captured = nullptr, uint64_t max_geometry_count = 0);
OpBatch HostCopyOps(const VkCopyAccelerationStructureInfoKHR& info);
OpBatch HostCopyToMemoryOps(const VkCopyAccelerationStructureToMemoryInfoKHR& info);
OpBatch HostCopyMemoryToOps(const VkCopyMemoryToAccelerationStructureInfoKHR& info);
OpBatch HostWritePropertiesOps(uint32_t count, const VkAccelerationStructureKHR* structures, VkQueryType type);

// After a host command's downcall: applies its operations when it completed successfully, keeps them for the
// deferred operation when it was deferred, drops them when it failed.
// `capture`: what the operations' captures point into (host builds), kept alive until they are applied.
void FinishHostOps(DeviceState& state, OpBatch batch, VkDeferredOperationKHR deferred, VkResult result,
                   std::shared_ptr<CaptureLog> capture = nullptr);
// Serialization sizes a successful vkWriteAccelerationStructuresPropertiesKHR wrote to pData.
void RecordHostSerializationSizes(DeviceState& state, uint32_t count, const VkAccelerationStructureKHR* structures,
                                  const void* data, size_t stride);

// ---- deferred operations ----
// A deferred operation completed (result: its own result). Applies its operations on success.
void CompleteDeferredOps(DeviceState& state, VkDeferredOperationKHR deferred, VkResult result);
bool HasDeferredOps(const DeviceState& state, VkDeferredOperationKHR deferred);

// ---- query results ----
// vkGetQueryPoolResults returned: serialization sizes of structures whose property write was submitted.
void RecordQueryResults(DeviceState& state, VkQueryPool pool, uint32_t first_query, uint32_t query_count,
                        size_t data_size, const void* data, VkDeviceSize stride, VkQueryResultFlags flags,
                        VkResult result);

}  // namespace asval
