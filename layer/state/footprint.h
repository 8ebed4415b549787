#pragma once
// The layer's own footprint on one device: how many objects the shadow state tracks and how much the layer holds
// for them (histories, serialized blobs, query slots, capture logs, the capture's slabs of device memory and its
// pending submissions), counted from the containers that hold them when asked (vkDestroyDevice, tests), never in
// the hot path. With the peaks that the containers that can grow keep under the locks they already take, one
// report at the end of a run says whether anything grew with the run's length (bench/longrun, issue 14).
#include <cstddef>
#include <cstdint>

namespace asval {

class DeviceState;

// What layer/capture holds (CapturePool::AddFootprint, CaptureTracker::AddFootprint).
struct CaptureFootprint {
  std::size_t slabs = 0;             // slabs of layer-owned host-visible device memory, in use or free
  std::size_t slabs_in_use = 0;      // held by capture logs now
  uint64_t slab_bytes = 0;           // device memory of all the slabs
  std::size_t peak_slabs_in_use = 0;
  std::size_t pending_submissions = 0;  // submissions carrying captures whose completion is not processed yet
  std::size_t peak_pending_submissions = 0;
  std::size_t spare_fences = 0;  // the layer's fences kept for submissions without one
};

struct LayerFootprint {
  // Shadow objects.
  std::size_t memories = 0;
  std::size_t buffers = 0;
  std::size_t structures = 0;
  std::size_t address_ranges = 0;  // the device-address map's entries
  std::size_t host_mappings = 0;
  std::size_t command_buffers = 0;
  // Operations in the published recordings of those command buffers (what a submission applies).
  std::size_t recorded_operations = 0;
  // Capture logs the command buffers hold (their own recording's and those of the published recordings, which
  // include the executed secondaries'), counted once each, and the slabs and captured bytes they hold.
  std::size_t capture_logs = 0;
  std::size_t capture_log_slabs = 0;
  uint64_t capture_log_bytes = 0;
  // The history store (HistoryStore::Sizes).
  std::size_t history_records = 0;
  std::size_t history_record_slots = 0;  // records_ entries, free ones included
  std::size_t history_spans = 0;
  std::size_t serialized_blobs = 0;
  std::size_t query_slots = 0;
  std::size_t spare_transactions = 0;
  std::size_t peak_history_records = 0;
  std::size_t peak_serialized_blobs = 0;
  std::size_t peak_query_slots = 0;
  std::size_t query_pools = 0;
  std::size_t deferred_operations = 0;
  // Memoized driver answers.
  std::size_t build_size_entries = 0;
  CaptureFootprint capture;
};

// The shadow state's part, counted under each container's own lock, one container at a time (consistent per
// container, not one instant: exact when no other thread changes the state, as at vkDestroyDevice). The capture
// part is left empty (layer/capture's owners fill it: ComputeFootprint below).
LayerFootprint ComputeStateFootprint(const DeviceState& state);

// The whole footprint: the state's and what the capture's pool and tracker hold (either may be null: capture off).
template <typename Pool, typename Tracker>
LayerFootprint ComputeFootprint(const DeviceState& state, Pool* pool, Tracker* tracker) {
  LayerFootprint f = ComputeStateFootprint(state);
  if (pool) pool->AddFootprint(&f.capture);
  if (tracker) tracker->AddFootprint(&f.capture);
  return f;
}

}  // namespace asval
