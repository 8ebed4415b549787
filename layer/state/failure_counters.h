#pragma once
// What the layer's own failures made it skip (issue 14, failure paths): its allocations (std::bad_alloc caught
// where the state write happens), its capture memory, and its own Vulkan objects (fences, the reducing pipeline).
// Each failure ends in a state the checks already treat as unknown (an object the layer does not know, a lost
// recording, an unknown history, bytes not captured), whose checks are skipped and counted, never guessed; these
// counters say how often and why, in ASVAL-History-Summary at vkDestroyDevice (layer/checks/history_host.cpp).
// Held in CaptureCounters (capture_log.h), which every writer can reach: DeviceState::capture_counters.
#include <atomic>
#include <cstdint>

namespace asval {

struct FailureCounters {
  // std::bad_alloc caught in the layer (every site below, and a second failure while handling one).
  std::atomic<uint64_t> allocation_failures{0};
  // Shadow records not made (memory, buffers and their bindings, structures, command pools and buffers, query
  // pools, mappings): the handles are unknown to the layer, their checks skipped and counted as for objects the
  // layer never saw.
  std::atomic<uint64_t> objects_untracked{0};
  // Command-buffer recordings marked lost (an operation not appended, or the snapshot not published): their
  // submissions make every structure's history unknown.
  std::atomic<uint64_t> recordings_lost{0};
  // Host commands whose operations could not be built, kept or applied: every structure's history made unknown.
  std::atomic<uint64_t> host_commands_lost{0};
  // Submissions whose history apply (or undo) failed: every structure's history made unknown from there on.
  std::atomic<uint64_t> submissions_unknown{0};
  // Operations of those submissions whose checks were not run (the failed one and those after it).
  std::atomic<uint64_t> operations_unchecked{0};
  // Structures whose history the failures above made unknown (also in HistoryStore::structures_made_unknown).
  std::atomic<uint64_t> structures_made_unknown{0};
  // Capture: slabs the device could not give (vkCreateBuffer / vkAllocateMemory / vkMapMemory of the layer's).
  std::atomic<uint64_t> capture_memory_failures{0};
  // Capture: commands (builds, host builds, serializations) whose captures were dropped by an allocation failure
  // while they were recorded.
  std::atomic<uint64_t> capture_commands_dropped{0};
  // The layer's own Vulkan objects that could not be made (its fence, its reducing pipeline).
  std::atomic<uint64_t> inserted_failures{0};
  // Submissions whose captures were never read (no fence could tell their completion, or processing them failed),
  // and the capture checks that were therefore not run (activity comparisons, instance and indirect range checks).
  std::atomic<uint64_t> submissions_captures_unread{0};
  std::atomic<uint64_t> capture_checks_unread{0};
  // The reducing pipeline could not be made: the captures are copied instead (nothing skipped).
  std::atomic<bool> reduce_pipeline_failed{false};
  // A structure's, or a buffer's (its creation or binding), shadow record could not be made: the layer no longer
  // knows every such object of the device, so a handle or device address it does not find may be that object's.
  // The checks that would report one as invalid skip and count instead (never cleared: one unknown is enough).
  std::atomic<bool> structures_incomplete{false};
  std::atomic<bool> buffers_incomplete{false};

  bool any() const {
    return allocation_failures.load(std::memory_order_relaxed) != 0 ||
           capture_memory_failures.load(std::memory_order_relaxed) != 0 ||
           inserted_failures.load(std::memory_order_relaxed) != 0;
  }
};

}  // namespace asval
