#include "history_record.h"

#include <fmt/format.h>

#include <cstring>
#include <new>

#include "history_apply.h"
#include "history_findings.h"
#include "history_submit.h"
#include "update_rules.h"

namespace asval {

namespace {

// The log of a command buffer being recorded, or null when history is off or the command buffer unknown
// (then the submission marks everything unknown: see SubmitHistory::Apply).
std::shared_ptr<CommandBufferLog> LogFor(DeviceState& state, uint32_t enabled, VkCommandBuffer cb) {
  if (!HistoryTracked(enabled)) return nullptr;
  return state.history.command_buffers.Find(cb);
}

// Runs an append; an allocation failure leaves the log marked lost rather than silently incomplete.
template <typename F>
void Guarded(CommandBufferLog& log, F&& append) {
  try {
    append();
  } catch (const std::bad_alloc&) {
    log.lost = true;
  }
}

OpOrigin DeviceOrigin(CommandBufferLog& log, OpCommand command, VkCommandBuffer cb) {
  OpOrigin origin;
  origin.command = command;
  origin.ordinal = log.NextOrdinal(command);
  origin.command_buffer = cb;
  return origin;
}

OpOrigin HostOrigin(OpCommand command) {
  OpOrigin origin;
  origin.command = command;
  return origin;
}

// The memory behind a device address that serialized data is written to or read from.
SerializedLocation ResolveDeviceLocation(const DeviceState& state, VkDeviceAddress address) {
  SerializedLocation where;
  where.device_address = address;
  AddressHits hits;
  state.buffer_addresses.FindContaining(address, hits);
  for (const AddressHit& hit : hits) {
    const VkDeviceSize remaining = hit.base + hit.size - address;
    if (remaining <= where.capacity) continue;
    std::optional<std::shared_ptr<const BufferState>> buffer = state.buffers.find(hit.buffer);
    if (!buffer || !*buffer || !(*buffer)->bound) continue;
    const MemoryBinding binding{(*buffer)->memory, (*buffer)->memory_offset, true};
    std::optional<MemorySpan> span = ResolveMemorySpan(binding, address - hit.base, remaining);
    if (!span) continue;
    where.span = *span;
    where.capacity = remaining;
  }
  return where;
}

AsOp CopyOp(const VkCopyAccelerationStructureInfoKHR& info) {
  AsOp op;
  op.kind = OpKind::kCopy;
  op.src = info.src;
  op.dst = info.dst;
  op.copy_mode = info.mode;
  return op;
}

AsOp SerializeOp(const VkCopyAccelerationStructureToMemoryInfoKHR& info) {
  AsOp op;
  op.kind = OpKind::kSerialize;
  op.src = info.src;
  op.copy_mode = info.mode;
  return op;
}

AsOp DeserializeOp(const VkCopyMemoryToAccelerationStructureInfoKHR& info) {
  AsOp op;
  op.kind = OpKind::kDeserialize;
  op.dst = info.dst;
  op.copy_mode = info.mode;
  return op;
}

void ApplyNow(DeviceState& state, const OpBatch& batch) {
  std::unique_lock<std::mutex> lock = state.history.store.Lock();
  for (const AsOp& op : batch.ops()) ApplyOp(state, state.history.store, batch, op, nullptr);
}

}  // namespace

// ---- device commands -----------------------------------------------------------------------------------------

void RecordDeviceBuild(DeviceState& state, uint32_t enabled, const BuildCommand& cmd) {
  std::shared_ptr<CommandBufferLog> log = LogFor(state, enabled, cmd.command_buffer);
  if (!log || !cmd.infos) return;
  const OpCommand command = cmd.is_indirect() ? OpCommand::kCmdBuildIndirect : OpCommand::kCmdBuild;
  const OpOrigin origin = DeviceOrigin(*log, command, cmd.command_buffer);
  // Indirect builds: the ranges (and so the primitive counts) are on the device.
  const VkAccelerationStructureBuildRangeInfoKHR* const* ranges = cmd.is_indirect() ? nullptr : cmd.ranges;
  Guarded(*log, [&] { log->batch.AppendBuilds(origin, cmd.info_count, cmd.infos, ranges); });
}

void RecordDeviceCopy(DeviceState& state, uint32_t enabled, VkCommandBuffer cb,
                      const VkCopyAccelerationStructureInfoKHR& info) {
  std::shared_ptr<CommandBufferLog> log = LogFor(state, enabled, cb);
  if (!log) return;
  AsOp op = CopyOp(info);
  op.origin = DeviceOrigin(*log, OpCommand::kCmdCopy, cb);
  Guarded(*log, [&] { log->batch.Append(op); });
}

void RecordDeviceCopyToMemory(DeviceState& state, uint32_t enabled, VkCommandBuffer cb,
                              const VkCopyAccelerationStructureToMemoryInfoKHR& info) {
  std::shared_ptr<CommandBufferLog> log = LogFor(state, enabled, cb);
  if (!log) return;
  AsOp op = SerializeOp(info);
  op.origin = DeviceOrigin(*log, OpCommand::kCmdCopyToMemory, cb);
  op.memory = ResolveDeviceLocation(state, info.dst.deviceAddress);
  Guarded(*log, [&] { log->batch.Append(op); });
}

void RecordDeviceCopyMemoryTo(DeviceState& state, uint32_t enabled, VkCommandBuffer cb,
                              const VkCopyMemoryToAccelerationStructureInfoKHR& info) {
  std::shared_ptr<CommandBufferLog> log = LogFor(state, enabled, cb);
  if (!log) return;
  AsOp op = DeserializeOp(info);
  op.origin = DeviceOrigin(*log, OpCommand::kCmdCopyMemoryTo, cb);
  op.memory = ResolveDeviceLocation(state, info.src.deviceAddress);
  Guarded(*log, [&] { log->batch.Append(op); });
}

void RecordDeviceWriteProperties(DeviceState& state, uint32_t enabled, VkCommandBuffer cb, uint32_t count,
                                 const VkAccelerationStructureKHR* structures, VkQueryType type, VkQueryPool pool,
                                 uint32_t first_query) {
  std::shared_ptr<CommandBufferLog> log = LogFor(state, enabled, cb);
  if (!log || !structures) return;
  const OpOrigin origin = DeviceOrigin(*log, OpCommand::kCmdWriteProperties, cb);
  Guarded(*log, [&] {
    for (uint32_t i = 0; i < count; ++i) {
      AsOp op;
      op.kind = OpKind::kWriteProperties;
      op.origin = origin;
      op.origin.element = i;
      op.dst = structures[i];
      op.query_type = type;
      op.query_pool = pool;
      op.query = first_query + i;
      log->batch.Append(op);
    }
  });
}

void ResetCommandBufferLog(DeviceState& state, VkCommandBuffer cb) {
  if (std::shared_ptr<CommandBufferLog> log = state.history.command_buffers.Find(cb)) log->Clear();
}

void RecordExecuteCommands(DeviceState& state, uint32_t enabled, VkCommandBuffer primary, uint32_t count,
                           const VkCommandBuffer* secondaries) {
  std::shared_ptr<CommandBufferLog> log = LogFor(state, enabled, primary);
  if (!log || !secondaries) return;
  for (uint32_t i = 0; i < count; ++i) {
    std::shared_ptr<CommandBufferLog> secondary = state.history.command_buffers.Find(secondaries[i]);
    if (!secondary || secondary->lost) {
      log->lost = true;
      continue;
    }
    if (secondary->batch.empty()) continue;
    Guarded(*log, [&] { log->batch.AppendExecuted(secondary->batch, primary); });
  }
}

// ---- host commands -------------------------------------------------------------------------------------------

bool CheckHostOps(const DeviceState& state, Reporter& reporter, uint32_t enabled, const OpBatch& batch,
                  const char* function) {
  if (!HistoryTracked(enabled) || batch.empty()) return false;
  HistoryFindings findings;
  {
    std::unique_lock<std::mutex> lock = state.history.store.Lock();
    const HistoryCheckSite site{Location(function), VK_NULL_HANDLE, false};
    for (const AsOp& op : batch.ops()) CheckOpHistory(state, state.history.store, enabled, batch, op, site, findings);
  }
  return findings.ReportAll(reporter);
}

void FinishHostOps(DeviceState& state, uint32_t enabled, OpBatch batch, VkDeferredOperationKHR deferred,
                   VkResult result) {
  if (!HistoryTracked(enabled)) return;
  if (result == VK_SUCCESS || result == VK_OPERATION_NOT_DEFERRED_KHR) {
    ApplyNow(state, batch);
  } else if (result == VK_OPERATION_DEFERRED_KHR && deferred) {
    auto pending = std::make_unique<DeferredHostOps>();
    pending->batch = std::move(batch);
    std::lock_guard<std::mutex> lock(state.history.deferred_mutex);
    auto [it, inserted] = state.history.deferred.try_emplace(deferred, std::move(pending));
    if (!inserted) it->second->batch.AppendExecuted(pending->batch, VK_NULL_HANDLE);
  }
  // Any other result: the command failed and changed nothing the layer can rely on.
}

bool ValidateBuildHistory(const CheckContext& ctx, const BuildCommand& cmd) {
  if (!cmd.is_host() || !cmd.infos) return false;  // device builds: checked at submission
  OpBatch batch;
  batch.AppendBuilds(HostOrigin(OpCommand::kHostBuild), cmd.info_count, cmd.infos, cmd.ranges);
  return CheckHostOps(ctx.state, ctx.reporter, ctx.enabled_checks, batch, cmd.function);
}

void FinishHostBuild(DeviceState& state, uint32_t enabled, const BuildCommand& cmd, VkResult result) {
  if (!HistoryTracked(enabled) || !cmd.infos) return;
  OpBatch batch;
  batch.AppendBuilds(HostOrigin(OpCommand::kHostBuild), cmd.info_count, cmd.infos, cmd.ranges);
  FinishHostOps(state, enabled, std::move(batch), cmd.deferred_operation, result);
}

OpBatch HostCopyOps(const VkCopyAccelerationStructureInfoKHR& info) {
  OpBatch batch;
  AsOp op = CopyOp(info);
  op.origin = HostOrigin(OpCommand::kHostCopy);
  batch.Append(op);
  return batch;
}

OpBatch HostCopyToMemoryOps(const VkCopyAccelerationStructureToMemoryInfoKHR& info) {
  OpBatch batch;
  AsOp op = SerializeOp(info);
  op.origin = HostOrigin(OpCommand::kHostCopyToMemory);
  op.memory.host_address = info.dst.hostAddress;
  batch.Append(op);
  return batch;
}

OpBatch HostCopyMemoryToOps(const VkCopyMemoryToAccelerationStructureInfoKHR& info) {
  OpBatch batch;
  AsOp op = DeserializeOp(info);
  op.origin = HostOrigin(OpCommand::kHostCopyMemoryTo);
  op.memory.host_address = info.src.hostAddress;
  batch.Append(op);
  return batch;
}

OpBatch HostWritePropertiesOps(uint32_t count, const VkAccelerationStructureKHR* structures, VkQueryType type) {
  OpBatch batch;
  for (uint32_t i = 0; structures && i < count; ++i) {
    AsOp op;
    op.kind = OpKind::kWriteProperties;
    op.origin = HostOrigin(OpCommand::kHostWriteProperties);
    op.origin.element = i;
    op.dst = structures[i];
    op.query_type = type;
    batch.Append(op);
  }
  return batch;
}

void RecordHostSerializationSizes(DeviceState& state, uint32_t count, const VkAccelerationStructureKHR* structures,
                                  const void* data, size_t stride) {
  if (!structures || !data) return;
  HistoryStore& store = state.history.store;
  std::unique_lock<std::mutex> lock = store.Lock();
  for (uint32_t i = 0; i < count; ++i) {
    uint64_t size = 0;
    std::memcpy(&size, static_cast<const unsigned char*>(data) + i * stride, sizeof(size));
    if (const AsHistory* h = store.Find(structures[i])) {
      RecordSerializationSize(store, structures[i], h->generation, size);
    }
  }
}

// ---- deferred operations -------------------------------------------------------------------------------------

void CompleteDeferredOps(DeviceState& state, VkDeferredOperationKHR deferred, VkResult result) {
  std::unique_ptr<DeferredHostOps> pending;
  {
    std::lock_guard<std::mutex> lock(state.history.deferred_mutex);
    auto it = state.history.deferred.find(deferred);
    if (it == state.history.deferred.end()) return;
    pending = std::move(it->second);
    state.history.deferred.erase(it);
  }
  if (result == VK_SUCCESS) ApplyNow(state, pending->batch);
}

bool HasDeferredOps(DeviceState& state, VkDeferredOperationKHR deferred) {
  std::lock_guard<std::mutex> lock(state.history.deferred_mutex);
  return state.history.deferred.count(deferred) != 0;
}

// ---- query results -------------------------------------------------------------------------------------------

void RecordQueryResults(DeviceState& state, VkQueryPool pool, uint32_t first_query, uint32_t query_count,
                        size_t data_size, const void* data, VkDeviceSize stride, VkQueryResultFlags flags,
                        VkResult result) {
  if (!data || (result != VK_SUCCESS && result != VK_NOT_READY)) return;
  HistoryStore& store = state.history.store;
  std::unique_lock<std::mutex> lock = store.Lock();
  const bool wide = (flags & VK_QUERY_RESULT_64_BIT) != 0;
  const size_t value_size = wide ? 8 : 4;
  const bool availability = (flags & VK_QUERY_RESULT_WITH_AVAILABILITY_BIT) != 0;
  for (uint32_t i = 0; i < query_count; ++i) {
    const QuerySlot* slot = store.FindSlot(pool, first_query + i);
    if (!slot || slot->type != VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR) continue;
    const size_t offset = static_cast<size_t>(stride) * i;
    if (offset + value_size * (availability ? 2 : 1) > data_size) break;
    const auto* bytes = static_cast<const unsigned char*>(data) + offset;
    uint64_t value = 0, available = result == VK_SUCCESS ? 1 : 0;
    if (wide) {
      std::memcpy(&value, bytes, 8);
      if (availability) std::memcpy(&available, bytes + 8, 8);
    } else {
      uint32_t v32 = 0, a32 = 0;
      std::memcpy(&v32, bytes, 4);
      value = v32;
      if (availability) {
        std::memcpy(&a32, bytes + 4, 4);
        available = a32;
      }
    }
    // VK_QUERY_RESULT_PARTIAL_BIT values of unavailable queries are not final.
    if (!available) continue;
    RecordSerializationSize(store, slot->as, slot->generation, value);
  }
}

// ---- lifetime ------------------------------------------------------------------------------------------------

void ForgetHistory(DeviceState& state, VkAccelerationStructureKHR as) {
  std::unique_lock<std::mutex> lock = state.history.store.Lock();
  state.history.store.Forget(as);
}

void ReportHistorySummary(const DeviceState& state, Reporter& reporter, VkDevice device) {
  const HistoryStore& store = state.history.store;
  const uint64_t skipped = store.rules_skipped_unknown_history.load(std::memory_order_relaxed);
  if (skipped == 0) return;
  reporter.Report(Severity::kInfo, kHistorySummaryId, Location("vkDestroyDevice"),
                  {Obj(VK_OBJECT_TYPE_DEVICE, device)},
                  fmt::format("{} history checks were skipped because the history they need was unknown "
                              "({} structures got an unknown history: deserialized from bytes the layer did not see "
                              "serialized, copied from such a structure, or operations the layer could not record). "
                              "{} operations were applied in execution order.",
                              skipped, store.structures_made_unknown.load(std::memory_order_relaxed),
                              store.ops_applied.load(std::memory_order_relaxed)));
}

}  // namespace asval
