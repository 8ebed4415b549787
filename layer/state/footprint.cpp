#include "footprint.h"

#include <memory>
#include <mutex>
#include <unordered_set>
#include <vector>

#include "device_state.h"

namespace asval {

namespace {

// A capture log counted once however many recordings hold it (a primary's published recording holds its
// secondaries' logs too).
void CountLog(const std::shared_ptr<CaptureLog>& log, std::unordered_set<const CaptureLog*>& seen,
              LayerFootprint& f) {
  if (!log || !seen.insert(log.get()).second) return;
  ++f.capture_logs;
  f.capture_log_slabs += log->slabs.size();
  f.capture_log_bytes += log->bytes_captured;
}

// Reads each command buffer's own capture log, which only its recording thread writes: counted when no command
// buffer is being recorded (vkDestroyDevice, tests).
void CountCommandBuffers(const CommandBufferMap& command_buffers, LayerFootprint& f) {
  std::unordered_set<const CaptureLog*> seen;
  for (const std::shared_ptr<CommandBufferState>& cb : command_buffers.All()) {
    ++f.command_buffers;
    CountLog(cb->capture_log, seen, f);
    for (const std::shared_ptr<CaptureLog>& log : cb->executed_capture_logs) CountLog(log, seen, f);
    if (const std::shared_ptr<const RecordedOps> published = cb->Executable()) {
      f.recorded_operations += published->batch.ops().size();
      for (const std::shared_ptr<CaptureLog>& log : published->capture_logs) CountLog(log, seen, f);
    }
  }
}

}  // namespace

LayerFootprint ComputeStateFootprint(const DeviceState& state) {
  LayerFootprint f;
  f.memories = state.memories.size();
  f.buffers = state.buffers.size();
  f.structures = state.acceleration_structures.size();
  f.address_ranges = state.buffer_addresses.size();
  f.host_mappings = state.host_mappings.size();
  CountCommandBuffers(state.command_buffers, f);
  {
    std::unique_lock<std::mutex> lock = state.history.store.Lock();
    const HistoryStore::Sizes s = state.history.store.sizes();
    f.history_records = s.records;
    f.history_record_slots = s.record_slots;
    f.history_spans = s.spans;
    f.serialized_blobs = s.blobs;
    f.query_slots = s.query_slots;
    f.spare_transactions = s.spare_transactions;
    f.peak_history_records = s.peak_records;
    f.peak_serialized_blobs = s.peak_blobs;
    f.peak_query_slots = s.peak_query_slots;
  }
  f.query_pools = state.history.query_pools.size();
  {
    std::lock_guard<std::mutex> lock(state.history.deferred_mutex);
    f.deferred_operations = state.history.deferred.size();
  }
  f.build_size_entries = state.build_sizes.size();
  return f;
}

}  // namespace asval
