#pragma once
// Recording side of the build history: what the hooks call after a successful downcall.
//   device commands: append operations to the command buffer's log (applied at submission, history_submit.h);
//   host commands:   checked against the histories when called, applied when they complete (at once, or when
//                    the deferred operation is seen to complete).
// Nothing here runs when the settings disable both the history and the copies families.
#include <vulkan/vulkan.h>

#include "build_command.h"
#include "check_context.h"
#include "device_state.h"

namespace asval {

// ---- device commands (after the downcall) ----
void RecordDeviceBuild(DeviceState& state, uint32_t enabled_checks, const BuildCommand& cmd);
void RecordDeviceCopy(DeviceState& state, uint32_t enabled_checks, VkCommandBuffer cb,
                      const VkCopyAccelerationStructureInfoKHR& info);
void RecordDeviceCopyToMemory(DeviceState& state, uint32_t enabled_checks, VkCommandBuffer cb,
                              const VkCopyAccelerationStructureToMemoryInfoKHR& info);
void RecordDeviceCopyMemoryTo(DeviceState& state, uint32_t enabled_checks, VkCommandBuffer cb,
                              const VkCopyMemoryToAccelerationStructureInfoKHR& info);
void RecordDeviceWriteProperties(DeviceState& state, uint32_t enabled_checks, VkCommandBuffer cb, uint32_t count,
                                 const VkAccelerationStructureKHR* structures, VkQueryType type, VkQueryPool pool,
                                 uint32_t first_query);
// vkBeginCommandBuffer, vkResetCommandBuffer: the log starts empty.
void ResetCommandBufferLog(DeviceState& state, VkCommandBuffer cb);
// vkCmdExecuteCommands: the secondaries' operations join the primary's log, in order.
void RecordExecuteCommands(DeviceState& state, uint32_t enabled_checks, VkCommandBuffer primary, uint32_t count,
                           const VkCommandBuffer* secondaries);

// ---- host commands ----
// The history family's line in the build-family table: host builds are checked when called (device builds
// when submitted, so this does nothing for them).
bool ValidateBuildHistory(const CheckContext& ctx, const BuildCommand& cmd);
// After vkBuildAccelerationStructuresKHR's downcall.
void FinishHostBuild(DeviceState& state, uint32_t enabled_checks, const BuildCommand& cmd, VkResult result);

// Host copies and property writes: one operation each (several for property writes).
OpBatch HostCopyOps(const VkCopyAccelerationStructureInfoKHR& info);
OpBatch HostCopyToMemoryOps(const VkCopyAccelerationStructureToMemoryInfoKHR& info);
OpBatch HostCopyMemoryToOps(const VkCopyMemoryToAccelerationStructureInfoKHR& info);
OpBatch HostWritePropertiesOps(uint32_t count, const VkAccelerationStructureKHR* structures, VkQueryType type);
// Checks host operations against the histories now; reports. True when a callback asked to skip the call.
bool CheckHostOps(const DeviceState& state, Reporter& reporter, uint32_t enabled_checks, const OpBatch& batch,
                  const char* function);
// After a host command's downcall: applies its operations when it completed successfully, keeps them for the
// deferred operation when it was deferred, drops them when it failed.
void FinishHostOps(DeviceState& state, uint32_t enabled_checks, OpBatch batch, VkDeferredOperationKHR deferred,
                   VkResult result);
// Serialization sizes a successful vkWriteAccelerationStructuresPropertiesKHR wrote to pData.
void RecordHostSerializationSizes(DeviceState& state, uint32_t count, const VkAccelerationStructureKHR* structures,
                                  const void* data, size_t stride);

// ---- deferred operations ----
// A deferred operation completed (result: its own result). Applies its operations on success.
void CompleteDeferredOps(DeviceState& state, VkDeferredOperationKHR deferred, VkResult result);
bool HasDeferredOps(DeviceState& state, VkDeferredOperationKHR deferred);

// ---- query results ----
// vkGetQueryPoolResults returned: serialization sizes of structures whose property write was submitted.
void RecordQueryResults(DeviceState& state, VkQueryPool pool, uint32_t first_query, uint32_t query_count,
                        size_t data_size, const void* data, VkDeviceSize stride, VkQueryResultFlags flags,
                        VkResult result);

// vkDestroyAccelerationStructureKHR: the structure's history ends.
void ForgetHistory(DeviceState& state, VkAccelerationStructureKHR as);
// vkDestroyDevice: an info message (and JSON line) counting the history checks skipped for unknown history.
void ReportHistorySummary(const DeviceState& state, Reporter& reporter, VkDevice device);

}  // namespace asval
