#pragma once
// Build history of acceleration structures in execution order (issue 6).
//
// Each structure has a history record: never built, built (with the parameters of the build that was executed
// last, which an update must repeat), or unknown (the layer cannot know: deserialized from bytes it did not
// see written, copied from an unknown structure, or an operation was lost). Records change when operations are
// *applied*: at vkQueueSubmit for command buffers, in submission order, and when host commands complete.
//
// Everything here is guarded by one mutex per device (Lock()). Submissions are rare next to recordings, and
// one lock gives every submission a single total order, which is the order the layer assumes the device
// executes them in (host submission order; see docs/history.md).
//
// Changes made while applying a submission can be rolled back (Transaction) when the app's callback asks to
// skip the vkQueueSubmit or the driver rejects it: the submission then never happened.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <vector>

#include "build_activity.h"
#include "command_buffer_ops.h"
#include "concurrent_map.h"
#include "memory_range.h"

namespace asval {

// XXH3 (64 bits) over bytes: serialized data read back on the host, and small keys.
uint64_t HashBytes(const void* data, std::size_t size);

// What an update must repeat (VUIDs 03667, 03758..03767, 03769): the parameters of the last build.
// Immutable and shared: a clone or compaction shares its source's snapshot.
struct BuildSnapshot {
  VkBuildAccelerationStructureFlagsKHR flags = 0;
  VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  std::vector<GeometryRecord> geometries;
  OpOrigin origin;  // the build (or update) that produced it
};

enum class HistoryKind : uint8_t { kNeverBuilt, kBuilt, kUnknown };

enum class UnknownReason : uint8_t {
  kNone,
  kDeserializedUnknownBytes,  // the bytes were not serialized by a command the layer saw, or were modified since
  kDeserializedDeviceBytes,   // deserialized from device memory whose bytes the layer has not verified (or cannot)
  kCopiedFromUnknown,         // cloned, compacted or deserialized from a structure whose history is unknown
  kLostOperations,            // the layer could not record an operation (allocation failure) or a command buffer
  kUnreadableBuild,           // built by an invalid build whose geometries could not be read
};
const char* UnknownReasonText(UnknownReason reason);

// Another operation wrote memory that overlaps this structure's memory after it was built.
struct Clobber {
  OpOrigin by;
  VkAccelerationStructureKHR writer = VK_NULL_HANDLE;  // the structure that operation wrote; null for serialized bytes
};

struct AsHistory {
  HistoryKind kind = HistoryKind::kNeverBuilt;
  UnknownReason unknown_reason = UnknownReason::kNone;
  std::shared_ptr<const BuildSnapshot> build;  // set when kind == kBuilt
  std::optional<Clobber> clobbered;
  // Bumped by every change of the contents (build, update, copy, deserialization), device-wide unique.
  uint64_t generation = 0;
  // The serialization size the app read back for `serialization_size_generation` (0: none known).
  uint64_t serialization_size = 0;
  uint64_t serialization_size_generation = 0;
  // Where the structure's bytes are, once known (for aliasing clobbers).
  MemorySpan span;
  // The primitive activity of the build or update that last executed on it, from its captured inputs (filled
  // when that submission completes); null when that build was not captured (an update's activity rules are then
  // skipped and counted).
  std::shared_ptr<BuildActivity> activity;
};

// Bytes written by a serialization, with the history of the structure serialized.
struct SerializedBlob {
  uint64_t id = 0;
  // Device memory: span.begin is where the data starts, span.end how far it may reach (the serialization
  // size when known, else the end of the buffer). Host memory: host_address, host_size and host_hash.
  MemorySpan span;
  const void* host_address = nullptr;
  uint64_t host_size = 0;
  uint64_t host_hash = 0;
  AsHistory history;  // the source's record at serialization (kind, build snapshot, activity)
  bool valid = true;  // false once a tracked write overlapped the bytes
  // Device memory whose written bytes the capture copied (issue 12): where they start, and their content (size
  // and hash), filled when the serialization's submission completes. Null when not captured: a deserialization
  // from there then stays unknown.
  VkDeviceAddress device_address = 0;
  std::shared_ptr<SerializedContent> content;
};

// Query pool slots written by vkCmdWriteAccelerationStructuresPropertiesKHR: which structure (and contents
// generation) a serialization-size result belongs to, so that vkGetQueryPoolResults can attach it.
struct QuerySlot {
  VkAccelerationStructureKHR as = VK_NULL_HANDLE;
  uint64_t generation = 0;
  VkQueryType type = VK_QUERY_TYPE_OCCLUSION;
};

class HistoryStore;

// Undo log of one submission's changes.
class Transaction {
 public:
  bool empty() const { return entries_.empty(); }
  void ReserveMore(std::size_t entries) { entries_.reserve(entries_.size() + entries); }

 private:
  friend class HistoryStore;
  enum class Kind : uint8_t { kHistory, kBlobAdded, kBlobInvalidated, kSlot };
  struct Entry {
    Kind kind;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;
    std::optional<AsHistory> old_history;  // kHistory: nullopt when the record did not exist
    uint64_t version = 0;                  // kHistory / kSlot: the version this transaction wrote
    uint64_t old_version = 0;              // ... and the one it replaced (restored with the old value)
    uint64_t blob_id = 0;                  // kBlobAdded / kBlobInvalidated
    std::pair<VkQueryPool, uint32_t> slot_key{};
    std::optional<QuerySlot> old_slot;
  };
  std::vector<Entry> entries_;
};

class HistoryStore {
 public:
  std::unique_lock<std::mutex> Lock() const { return std::unique_lock<std::mutex>(mutex_); }

  // ---- everything below: with Lock() held ----

  // The record of a structure; never built when the layer has none.
  AsHistory Get(VkAccelerationStructureKHR as) const;
  const AsHistory* Find(VkAccelerationStructureKHR as) const;
  // Replaces the record (and indexes its span). txn may be null (host operations are not rolled back).
  void Set(VkAccelerationStructureKHR as, AsHistory history, Transaction* txn);
  // Destroyed: its history ends; a new structure with the same handle value starts fresh.
  void Forget(VkAccelerationStructureKHR as);
  uint64_t NextGeneration() { return ++generation_counter_; }

  // Structures whose span overlaps `span` (other than `except`).
  template <typename F>
  void ForEachOverlapping(const MemorySpan& span, VkAccelerationStructureKHR except, F&& f) const;

  // Serialized bytes.
  uint64_t AddBlob(SerializedBlob blob, Transaction* txn);
  const SerializedBlob* FindHostBlob(const void* host_address) const;
  // The latest valid blob of device memory that starts at span.begin of span.memory; null when none.
  const SerializedBlob* FindDeviceBlob(const MemorySpan& span) const;
  // The latest valid blob of device memory written at a device address; null when none (a hint only: the
  // address may have been rebound since).
  const SerializedBlob* FindDeviceBlobAt(VkDeviceAddress address) const;
  void InvalidateBlobsOverlapping(const MemorySpan& span, Transaction* txn);
  void InvalidateHostBlob(const void* host_address, Transaction* txn);
  void InvalidateAllBlobs(Transaction* txn);

  // Query slots.
  void SetSlot(VkQueryPool pool, uint32_t query, const QuerySlot& slot, Transaction* txn);
  const QuerySlot* FindSlot(VkQueryPool pool, uint32_t query) const;
  void ForgetPool(VkQueryPool pool);

  // vkFreeMemory: serialized bytes in that memory are gone, and spans there index nothing any more (a later
  // allocation may reuse the handle value). Not part of any transaction: freeing memory is not undone.
  void ForgetMemory(VkDeviceMemory memory);

  // Rolls a transaction back. Entries that a later change already replaced are left alone.
  void Undo(Transaction& txn);

  std::size_t size() const { return histories_.size(); }

  // Counters, readable without the lock.
  mutable std::atomic<uint64_t> ops_applied{0};
  mutable std::atomic<uint64_t> rules_skipped_unknown_history{0};  // history checks skipped: unknown history
  mutable std::atomic<uint64_t> structures_made_unknown{0};

 private:
  struct Record {
    AsHistory history;
    uint64_t version = 0;
  };
  struct SpanKey {
    VkDeviceMemory memory;
    VkDeviceSize begin;
    friend bool operator<(const SpanKey& a, const SpanKey& b) {
      return a.memory != b.memory ? a.memory < b.memory : a.begin < b.begin;
    }
  };
  struct SpanEntry {
    VkAccelerationStructureKHR as;
    VkDeviceSize end;
  };
  struct SlotKeyHash {
    std::size_t operator()(const std::pair<VkQueryPool, uint32_t>& k) const noexcept {
      const uint64_t words[2] = {reinterpret_cast<uint64_t>(k.first), k.second};
      return static_cast<std::size_t>(HashBytes(words, sizeof(words)));
    }
  };
  struct SlotRecord {
    QuerySlot slot;
    uint64_t version = 0;
  };

  void Unindex(VkAccelerationStructureKHR as, const MemorySpan& span);
  void Index(VkAccelerationStructureKHR as, const MemorySpan& span);

  mutable std::mutex mutex_;
  std::unordered_map<VkAccelerationStructureKHR, Record, HandleHash<VkAccelerationStructureKHR>> histories_;
  std::multimap<SpanKey, SpanEntry> spans_;
  std::unordered_map<VkDeviceMemory, VkDeviceSize, HandleHash<VkDeviceMemory>> longest_span_;
  std::vector<SerializedBlob> blobs_;
  std::unordered_map<std::pair<VkQueryPool, uint32_t>, SlotRecord, SlotKeyHash> slots_;
  uint64_t generation_counter_ = 0;
  uint64_t version_counter_ = 0;
  uint64_t blob_counter_ = 0;
};

template <typename F>
void HistoryStore::ForEachOverlapping(const MemorySpan& span, VkAccelerationStructureKHR except, F&& f) const {
  if (span.memory == VK_NULL_HANDLE || span.begin >= span.end) return;
  const auto longest = longest_span_.find(span.memory);
  if (longest == longest_span_.end()) return;
  const VkDeviceSize from = span.begin > longest->second ? span.begin - longest->second : 0;
  for (auto it = spans_.lower_bound(SpanKey{span.memory, from}); it != spans_.end(); ++it) {
    if (it->first.memory != span.memory || it->first.begin >= span.end) break;
    if (it->second.end > span.begin && it->second.as != except) f(it->second.as);
  }
}

}  // namespace asval
