#include "history_recorder.h"

#include <algorithm>
#include <cstring>
#include <new>

#include "failure_injection.h"
#include "history_apply.h"
#include "nv_structures.h"

namespace asval {

namespace {

// The command buffer being recorded, or null when history is off or the command buffer unknown (then the
// submission makes every structure's history unknown: see submission.h).
std::shared_ptr<CommandBufferState> Recording(DeviceState& state, VkCommandBuffer cb) {
  if (!state.history_tracked) return nullptr;
  return state.command_buffers.Find(cb);
}

// The same for the build commands, the hot path: through the thread's memo of the last command buffer
// (LastRecordedBuild, history_recorder.h).
CommandBufferState* RecordingBuild(DeviceState& state, VkCommandBuffer cb, LastRecordedBuild& last) {
  if (!state.history_tracked) return nullptr;
  const StampValue stamp = state.command_buffers.stamp();
  if (last.cb != cb || last.stamp != stamp) last = LastRecordedBuild{stamp, cb, state.command_buffers.Find(cb).get()};
  return last.state;
}

LastRecordedBuild& ThisThreadsLastRecordedBuild() {
  thread_local LastRecordedBuild last;
  return last;
}

// Runs an append; an allocation failure leaves the recording marked lost rather than silently incomplete (its
// submissions make every structure's history unknown), counted once per recording.
template <typename F>
void Guarded(const DeviceState& state, CommandBufferState& cb, F&& append) {
  try {
    InjectBadAlloc(FailSite::kRecording);
    append();
  } catch (const std::bad_alloc&) {
    FailureCounters& failures = state.failures();
    failures.allocation_failures.fetch_add(1, std::memory_order_relaxed);
    if (!cb.recording_lost) failures.recordings_lost.fetch_add(1, std::memory_order_relaxed);
    cb.recording_lost = true;
  }
}

// A host command's operations could not be built: an empty batch marked lost (allocates nothing).
OpBatch LostHostOps() {
  OpBatch lost;
  lost.MarkLost();
  return lost;
}

OpOrigin DeviceOrigin(const DeviceState& device, CommandBufferState& state, OpCommand command, VkCommandBuffer cb) {
  OpOrigin origin;
  origin.command = command;
  origin.ordinal = state.NextOrdinal(command);
  origin.command_buffer = cb;
  origin.recorded_at = device.LastObjectId();
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
    if (!buffer || !*buffer || !(*buffer)->bound || (*buffer)->memory == VK_NULL_HANDLE) continue;
    const MemoryBinding binding{(*buffer)->memory, (*buffer)->memory_offset, true};
    std::optional<MemorySpan> span = ResolveMemorySpan(binding, address - hit.base, remaining);
    if (!span) continue;
    where.span = *span;
    where.capacity = remaining;
  }
  return where;
}

// A copy (kCopy), serialization (kSerialize: no dst) or deserialization (kDeserialize: no src).
AsOp CopyKindOp(OpKind kind, VkAccelerationStructureKHR src, VkAccelerationStructureKHR dst,
                VkCopyAccelerationStructureModeKHR mode) {
  AsOp op;
  op.kind = kind;
  op.src = src;
  op.dst = dst;
  op.copy_mode = mode;
  return op;
}

// A serialization's or deserialization's captured bytes (index plus one in the recording's capture log, 0: none).
// The log lives as long as the published recording that holds the operation (RecordedOps::capture_logs).
void AttachBlobCapture(CommandBufferState& recording, uint32_t captured, AsOp& op) {
  if (captured == 0 || !recording.capture_log) return;
  op.capture_log = recording.capture_log.get();
  op.capture_info = captured - 1;
}

// A host command whose operations are lost (not built, not kept, or not applied): every structure's history is
// unknown from now on. The allocation that failed is counted here (a lost batch was built where no counter is at
// hand).
void HostOpsLost(DeviceState& state) {
  state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
  state.failures().host_commands_lost.fetch_add(1, std::memory_order_relaxed);
  std::unique_lock<std::mutex> lock = state.history.store.Lock();
  MakeAllUnknownAfterFailure(state, state.history.store);
}

void ApplyNow(DeviceState& state, const OpBatch& batch) {
  if (batch.lost()) return HostOpsLost(state);
  std::unique_lock<std::mutex> lock = state.history.store.Lock();
  std::size_t applied = 0;
  try {
    for (const AsOp& op : batch.ops()) {
      ApplyOp(state, state.history.store, batch, op, nullptr);
      ++applied;
    }
  } catch (const std::bad_alloc&) {
    // Host operations are not undoable: what was applied stays, and everything is unknown from here on (the
    // store's lock is held already).
    state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
    state.failures().host_commands_lost.fetch_add(1, std::memory_order_relaxed);
    MakeAllUnknownAfterFailure(state, state.history.store);
  }
  state.history.store.ops_applied.fetch_add(applied, std::memory_order_relaxed);
}

}  // namespace

// ---- device commands -----------------------------------------------------------------------------------------

void RecordCmdBuild(DeviceState& state, VkCommandBuffer cb, OpCommand command, uint32_t info_count,
                    const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                    const VkAccelerationStructureBuildRangeInfoKHR* const* ranges, LastRecordedBuild* last,
                    const uint32_t* captured) {
  CommandBufferState* recording = RecordingBuild(state, cb, last ? *last : ThisThreadsLastRecordedBuild());
  if (!recording || !infos) return;
  const OpOrigin origin = DeviceOrigin(state, *recording, command, cb);
  Guarded(state, *recording, [&] {
    recording->recording.AppendBuilds(origin, info_count, infos, ranges, recording->capture_log.get(), captured,
                                      state.properties.acceleration_structure.maxGeometryCount, state.lifetime_tracked);
  });
}

void RecordCmdCopy(DeviceState& state, VkCommandBuffer cb, const VkCopyAccelerationStructureInfoKHR& info) {
  std::shared_ptr<CommandBufferState> recording = Recording(state, cb);
  if (!recording) return;
  AsOp op = CopyKindOp(OpKind::kCopy, info.src, info.dst, info.mode);
  op.origin = DeviceOrigin(state, *recording, OpCommand::kCmdCopy, cb);
  Guarded(state, *recording, [&] { recording->recording.Append(op); });
}

void RecordCmdCopyToMemory(DeviceState& state, VkCommandBuffer cb,
                           const VkCopyAccelerationStructureToMemoryInfoKHR& info, uint32_t captured) {
  std::shared_ptr<CommandBufferState> recording = Recording(state, cb);
  if (!recording) return;
  AsOp op = CopyKindOp(OpKind::kSerialize, info.src, VK_NULL_HANDLE, info.mode);
  op.origin = DeviceOrigin(state, *recording, OpCommand::kCmdCopyToMemory, cb);
  AttachBlobCapture(*recording, captured, op);
  Guarded(state, *recording, [&] {
    op.memory = ResolveDeviceLocation(state, info.dst.deviceAddress);  // may allocate (many buffers there)
    recording->recording.Append(op);
  });
}

void RecordCmdCopyMemoryTo(DeviceState& state, VkCommandBuffer cb,
                           const VkCopyMemoryToAccelerationStructureInfoKHR& info, uint32_t captured) {
  std::shared_ptr<CommandBufferState> recording = Recording(state, cb);
  if (!recording) return;
  AsOp op = CopyKindOp(OpKind::kDeserialize, VK_NULL_HANDLE, info.dst, info.mode);
  op.origin = DeviceOrigin(state, *recording, OpCommand::kCmdCopyMemoryTo, cb);
  AttachBlobCapture(*recording, captured, op);
  Guarded(state, *recording, [&] {
    op.memory = ResolveDeviceLocation(state, info.src.deviceAddress);  // may allocate (many buffers there)
    recording->recording.Append(op);
  });
}

void RecordCmdWriteProperties(DeviceState& state, VkCommandBuffer cb, uint32_t count,
                              const VkAccelerationStructureKHR* structures, VkQueryType type, VkQueryPool pool,
                              uint32_t first_query, OpCommand command) {
  std::shared_ptr<CommandBufferState> recording = Recording(state, cb);
  if (!recording || !structures) return;
  const OpOrigin origin = DeviceOrigin(state, *recording, command, cb);
  Guarded(state, *recording, [&] {
    for (uint32_t i = 0; i < count; ++i) {
      AsOp op;
      op.kind = OpKind::kWriteProperties;
      op.origin = origin;
      op.origin.element = i;
      op.dst = structures[i];
      op.query_type = type;
      op.query_pool = pool;
      op.query = first_query + i;
      recording->recording.Append(op);
    }
  });
}

namespace {

// Whether the layer can follow an NV structure's history: null, or a live NV structure whose handle value no live KHR
// structure shares. Otherwise counted: the command is not recorded.
bool NvTrackable(const DeviceState& state, VkAccelerationStructureNV handle) {
  if (handle == VK_NULL_HANDLE) return true;
  const std::optional<std::shared_ptr<const NvStructureState>> found = state.nv_structures.find(handle);
  if (found && *found && !(*found)->shares_key) return true;
  if (found && *found) state.checks_skipped_unknown_state.fetch_add(1, std::memory_order_relaxed);
  return !found || !*found;  // a handle the layer does not know: its operation is applied as any other's (Fresh)
}

}  // namespace

void RecordCmdBuildNV(DeviceState& state, VkCommandBuffer cb, const VkAccelerationStructureInfoNV& info, bool update,
                      VkAccelerationStructureNV dst, VkAccelerationStructureNV src) {
  std::shared_ptr<CommandBufferState> recording = Recording(state, cb);
  if (!recording || !NvTrackable(state, dst) || !NvTrackable(state, update ? src : VK_NULL_HANDLE)) return;
  const OpOrigin origin = DeviceOrigin(state, *recording, OpCommand::kCmdBuildNV, cb);
  Guarded(state, *recording, [&] {
    recording->recording.AppendNvBuild(origin, info, update, NvHistoryKey(dst), NvHistoryKey(src),
                                       state.properties.ray_tracing_nv.maxGeometryCount);
  });
}

void RecordCmdCopyNV(DeviceState& state, VkCommandBuffer cb, VkAccelerationStructureNV dst,
                     VkAccelerationStructureNV src, VkCopyAccelerationStructureModeKHR mode) {
  std::shared_ptr<CommandBufferState> recording = Recording(state, cb);
  if (!recording || !NvTrackable(state, dst) || !NvTrackable(state, src)) return;
  AsOp op = CopyKindOp(OpKind::kCopy, NvHistoryKey(src), NvHistoryKey(dst), mode);
  op.origin = DeviceOrigin(state, *recording, OpCommand::kCmdCopyNV, cb);
  Guarded(state, *recording, [&] { recording->recording.Append(op); });
}

void RecordCmdWritePropertiesNV(DeviceState& state, VkCommandBuffer cb, uint32_t count,
                                const VkAccelerationStructureNV* structures, VkQueryType type, VkQueryPool pool,
                                uint32_t first_query) {
  if (!structures) return;
  for (uint32_t i = 0; i < count; ++i) {
    if (!NvTrackable(state, structures[i])) return;
  }
  // The same layout as an array of KHR handles: NvHistoryKey is the handle's value.
  static_assert(sizeof(VkAccelerationStructureNV) == sizeof(VkAccelerationStructureKHR), "keys are handle values");
  RecordCmdWriteProperties(state, cb, count, reinterpret_cast<const VkAccelerationStructureKHR*>(structures), type,
                           pool, first_query, OpCommand::kCmdWritePropertiesNV);
}

void RecordBindComputePipeline(DeviceState& state, VkCommandBuffer cb, VkPipeline pipeline) {
  if (CommandBufferState* recording = RecordingBuild(state, cb, ThisThreadsLastRecordedBuild())) {
    recording->compute_pipeline = pipeline;
  }
}

namespace {

// Before secondary `index` (whose recording is `ops`) executes again in `recording`: each of its capture logs that
// the recording already reads is copied, by the device, into a log of its own, which the operations appended so
// far read from then on. A log that cannot be copied stays shared: the executions' captures are then read twice by
// one submission, unknown and counted there (history_apply.cpp), never guessed.
void SaveExecutedCaptures(DeviceState& state, CommandBufferState& recording, const RecordedOps& ops, uint32_t index,
                          CaptureSaver& saver) {
  const auto& held = recording.executed_capture_logs;
  bool passed_down = false;
  for (std::size_t k = 0; k < ops.capture_logs.size(); ++k) {
    const std::shared_ptr<CaptureLog>& log = ops.capture_logs[k];
    if (std::find(held.begin(), held.end(), log) == held.end()) continue;  // its first execution here
    if (std::find(ops.capture_logs.begin(), ops.capture_logs.begin() + k, log) != ops.capture_logs.begin() + k) {
      continue;  // listed twice by the secondary (a secondary it executes twice): saved once
    }
    if (!passed_down) {  // the executions so far are recorded before the copies
      saver.PassDown(index);
      passed_down = true;
    }
    std::shared_ptr<CaptureLog> copy;
    try {
      copy = log->EmptyCopy();
      if (copy) recording.executed_capture_logs.push_back(copy);  // held before the device may write it
    } catch (const std::bad_alloc&) {
      state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (!copy) {
      state.failures().capture_memory_failures.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if (saver.RecordCopy(*log, *copy)) recording.recording.MoveCaptures(log.get(), copy.get());
  }
}

}  // namespace

void RecordExecuteCommands(DeviceState& state, VkCommandBuffer primary, uint32_t count,
                           const VkCommandBuffer* secondaries, CaptureSaver* saver) {
  std::shared_ptr<CommandBufferState> recording = Recording(state, primary);
  if (!recording || !secondaries) return;
  recording->compute_pipeline = VK_NULL_HANDLE;  // the primary's bound state is undefined after the secondaries
  // A protected primary may not write the layer's unprotected memory: its secondaries' captures stay shared.
  if (recording->is_protected) saver = nullptr;
  for (uint32_t i = 0; i < count; ++i) {
    Guarded(state, *recording, [&] { recording->secondaries.push_back(secondaries[i]); });
    const std::shared_ptr<CommandBufferState> secondary = state.command_buffers.Find(secondaries[i]);
    if (!secondary) {
      recording->recording_lost = true;
      continue;
    }
    // The secondary's last completed recording: another thread may be re-recording it right now.
    const std::shared_ptr<const RecordedOps> ops = secondary->Executable();
    if (!ops) continue;
    if (ops->lost) recording->recording_lost = true;
    if (saver && !ops->capture_logs.empty()) SaveExecutedCaptures(state, *recording, *ops, i, *saver);
    Guarded(state, *recording, [&] {
      recording->recording.AppendExecuted(ops->batch, primary);
      recording->executed_capture_logs.insert(recording->executed_capture_logs.end(), ops->capture_logs.begin(),
                                              ops->capture_logs.end());
    });
  }
}

// ---- host commands -------------------------------------------------------------------------------------------

// Host commands' operations are built in the hook, before the checks: an allocation failure there gives a lost
// batch (LostHostOps), whose checks are skipped (ValidateHostOps) and whose application makes every structure's
// history unknown (FinishHostOps).
OpBatch HostBuildOps(uint32_t info_count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                     const VkAccelerationStructureBuildRangeInfoKHR* const* ranges, CaptureLog* capture,
                     const uint32_t* captured, uint64_t max_geometry_count) try {
  InjectBadAlloc(FailSite::kHostOps);
  OpBatch batch;
  if (infos) {
    batch.AppendBuilds(HostOrigin(OpCommand::kHostBuild), info_count, infos, ranges, capture, captured,
                       max_geometry_count);
  }
  return batch;
} catch (const std::bad_alloc&) {
  return LostHostOps();
}

OpBatch HostCopyOps(const VkCopyAccelerationStructureInfoKHR& info) try {
  InjectBadAlloc(FailSite::kHostOps);
  OpBatch batch;
  AsOp op = CopyKindOp(OpKind::kCopy, info.src, info.dst, info.mode);
  op.origin = HostOrigin(OpCommand::kHostCopy);
  batch.Append(op);
  return batch;
} catch (const std::bad_alloc&) {
  return LostHostOps();
}

OpBatch HostCopyToMemoryOps(const VkCopyAccelerationStructureToMemoryInfoKHR& info) try {
  InjectBadAlloc(FailSite::kHostOps);
  OpBatch batch;
  AsOp op = CopyKindOp(OpKind::kSerialize, info.src, VK_NULL_HANDLE, info.mode);
  op.origin = HostOrigin(OpCommand::kHostCopyToMemory);
  op.memory.host_address = info.dst.hostAddress;
  batch.Append(op);
  return batch;
} catch (const std::bad_alloc&) {
  return LostHostOps();
}

OpBatch HostCopyMemoryToOps(const VkCopyMemoryToAccelerationStructureInfoKHR& info) try {
  InjectBadAlloc(FailSite::kHostOps);
  OpBatch batch;
  AsOp op = CopyKindOp(OpKind::kDeserialize, VK_NULL_HANDLE, info.dst, info.mode);
  op.origin = HostOrigin(OpCommand::kHostCopyMemoryTo);
  op.memory.host_address = info.src.hostAddress;
  batch.Append(op);
  return batch;
} catch (const std::bad_alloc&) {
  return LostHostOps();
}

OpBatch HostWritePropertiesOps(uint32_t count, const VkAccelerationStructureKHR* structures, VkQueryType type) try {
  InjectBadAlloc(FailSite::kHostOps);
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
} catch (const std::bad_alloc&) {
  return LostHostOps();
}

void FinishHostOps(DeviceState& state, OpBatch batch, VkDeferredOperationKHR deferred, VkResult result,
                   std::shared_ptr<CaptureLog> capture) {
  if (!state.history_tracked || (batch.empty() && !batch.lost())) return;
  if (result == VK_SUCCESS || result == VK_OPERATION_NOT_DEFERRED_KHR) {
    ApplyNow(state, batch);
  } else if (result == VK_OPERATION_DEFERRED_KHR && deferred) {
    if (batch.lost()) return HostOpsLost(state);  // the operation may complete at any time: unknown from now on
    try {
      auto pending = std::make_unique<DeferredHostOps>();
      pending->batch = std::move(batch);
      if (capture) pending->captures.push_back(std::move(capture));
      std::lock_guard<std::mutex> lock(state.history.deferred_mutex);
      auto [it, inserted] = state.history.deferred.try_emplace(deferred, std::move(pending));
      if (!inserted) {
        it->second->batch.AppendExecuted(pending->batch, VK_NULL_HANDLE);
        for (auto& held : pending->captures) it->second->captures.push_back(std::move(held));
      }
    } catch (const std::bad_alloc&) {
      // Not kept for its completion: what it does is unknown from now on (an entry already there for this
      // deferred operation is still applied when it completes, and changes nothing unknown back to known wrongly:
      // it only holds operations that do execute).
      HostOpsLost(state);
    }
  }
  // Any other result: the command failed and changed nothing the layer can rely on.
}

void RecordHostSerializationSizes(DeviceState& state, uint32_t count, const VkAccelerationStructureKHR* structures,
                                  const void* data, size_t stride) {
  if (!state.history_tracked || !structures || !data) return;
  HistoryStore& store = state.history.store;
  std::unique_lock<std::mutex> lock = store.Lock();
  for (uint32_t i = 0; i < count; ++i) {
    uint64_t size = 0;
    std::memcpy(&size, static_cast<const unsigned char*>(data) + i * stride, sizeof(size));
    if (const AsHistory* h = store.Find(structures[i])) {
      try {
        RecordSerializationSize(store, structures[i], h->generation, size);
      } catch (const std::bad_alloc&) {
        // Not attached: the size stays unknown (what needs it is skipped and counted).
        state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);
      }
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

bool HasDeferredOps(const DeviceState& state, VkDeferredOperationKHR deferred) {
  std::lock_guard<std::mutex> lock(state.history.deferred_mutex);
  return state.history.deferred.count(deferred) != 0;
}

// ---- query results -------------------------------------------------------------------------------------------

void RecordQueryResults(DeviceState& state, VkQueryPool pool, uint32_t first_query, uint32_t query_count,
                        size_t data_size, const void* data, VkDeviceSize stride, VkQueryResultFlags flags,
                        VkResult result) {
  if (!state.history_tracked || !data || (result != VK_SUCCESS && result != VK_NOT_READY)) return;
  // Only serialization sizes interest the layer: other pools (timestamps, occlusion) cost one map lookup.
  const std::optional<QueryPoolState> pool_state = state.history.query_pools.find(pool);
  if (!pool_state || pool_state->type != VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR) return;
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
    try {
      RecordSerializationSize(store, slot->as, slot->generation, value);
    } catch (const std::bad_alloc&) {
      state.failures().allocation_failures.fetch_add(1, std::memory_order_relaxed);  // the size stays unknown
    }
  }
}

}  // namespace asval
