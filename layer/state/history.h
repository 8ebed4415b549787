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
#include "handle_index.h"
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

// Whether two builds made structures of the same geometry layout: as many geometries, of the same types in the
// same order (what a top level's instances index their shader binding table records by).
bool SameGeometryLayout(const BuildSnapshot& a, const BuildSnapshot& b);

enum class HistoryKind : uint8_t { kNeverBuilt, kBuilt, kUnknown };

enum class UnknownReason : uint8_t {
  kNone,
  kDeserializedUnknownBytes,  // the bytes were not serialized by a command the layer saw, or were modified since
  kDeserializedDeviceBytes,   // deserialized from device memory whose bytes the layer has not verified (or cannot)
  kCopiedFromUnknown,         // cloned, compacted or deserialized from a structure whose history is unknown
  kLostOperations,            // the layer could not record an operation (allocation failure) or a command buffer
  kUnreadableBuild,           // built by an invalid build whose geometries could not be read
  kStaleHandle,               // written by a command recorded with a structure destroyed since (its handle reused)
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

// Undo log of one submission's changes. Entries are plain values in flat arrays: a replaced record's old history
// is moved in, not copied, and the arrays keep their capacity when the log is reused (HistoryStore keeps spare
// logs for the submissions to come, so that a steady stream of submissions allocates nothing here).
class Transaction {
 public:
  bool empty() const { return entries_.empty(); }
  void ReserveMore(std::size_t entries) { entries_.reserve(entries_.size() + entries); }
  // Forgets every entry (the changes stay), keeping the capacity.
  void Clear() {
    entries_.clear();
    histories_.clear();
    blobs_.clear();
    slots_.clear();
  }

 private:
  friend class HistoryStore;
  enum class Kind : uint8_t { kHistory, kFlip, kBlobAdded, kBlobInvalidated, kSlot };
  // In the order the changes were made; `at` indexes the array of its kind. A record rewritten into its other
  // history slot (kFlip, HistoryStore::Rewrite) is undone by switching back: the entry holds all there is to it.
  struct Entry {
    Kind kind;
    uint32_t at = 0;
    VkAccelerationStructureKHR as = VK_NULL_HANDLE;  // kFlip
    uint64_t version = 0;                            // kFlip: the version the rewrite wrote
    uint64_t old_version = 0;                        // ... and the one it replaced
  };
  struct HistoryChange {
    HistoryChange(VkAccelerationStructureKHR as_, uint64_t version_, uint64_t old_version_, bool existed_,
                  AsHistory&& old)
        : as(as_), version(version_), old_version(old_version_), existed(existed_), old_history(std::move(old)) {}
    VkAccelerationStructureKHR as;
    uint64_t version;      // the version this transaction wrote
    uint64_t old_version;  // ... and the one it replaced (restored with the old record)
    bool existed;          // false: the record did not exist (undone by forgetting it)
    AsHistory old_history;
  };
  struct SlotChange {
    std::pair<VkQueryPool, uint32_t> key;
    uint64_t version;
    uint64_t old_version;
    std::optional<QuerySlot> old_slot;  // nullopt when the slot did not exist
  };
  // Given by HistoryStore::TakeTransaction for each submission (0: a log made elsewhere, which never flips).
  uint64_t id_ = 0;
  std::vector<Entry> entries_;
  std::vector<HistoryChange> histories_;
  std::vector<uint64_t> blobs_;  // kBlobAdded / kBlobInvalidated: the blob's id
  std::vector<SlotChange> slots_;
};

class HistoryStore {
 public:
  std::unique_lock<std::mutex> Lock() const { return std::unique_lock<std::mutex>(mutex_); }

  // ---- everything below: with Lock() held ----

  // The record of a structure; never built when the layer has none.
  AsHistory Get(VkAccelerationStructureKHR as) const;
  const AsHistory* Find(VkAccelerationStructureKHR as) const {
    const uint32_t record = RecordOf(as);
    return record == kNoRecord ? nullptr : &records_[record].history();
  }
  // Replaces the record (and indexes its span). txn may be null (host operations are not rolled back). Returns
  // the record's index (kNoRecord for VK_NULL_HANDLE, which gets none).
  uint32_t Set(VkAccelerationStructureKHR as, AsHistory history, Transaction* txn);

  // The same by record index, for an operation that reads a record and then replaces it (one lookup, not
  // three). An index stays valid until its structure is forgotten (Forget, Undo of its creation); kNoRecord: the
  // structure has no record.
  static constexpr uint32_t kNoRecord = HandleIndex::kNone;
  uint32_t RecordOf(VkAccelerationStructureKHR as) const {
    return index_.Find(reinterpret_cast<uint64_t>(as));
  }
  const AsHistory& HistoryAt(uint32_t record) const { return records_[record].history(); }
  // Replaces the history of record (of structure as) like Set.
  void SetAt(uint32_t record, VkAccelerationStructureKHR as, AsHistory history, Transaction* txn);
  // For an operation that rewrites the contents of a structure whose record knows its span: the record's history
  // becomes never built with `build` as its snapshot, without clobber, activity or serialization size, with the
  // same span and a new generation, for the caller to fill in; the old one is kept for txn's undo. The span does
  // not change, so it is not re-indexed.
  // The first rewrite of a record by a transaction writes the record's other history slot and keeps the old one
  // where it was (undo switches back: nothing is moved or copied into the log); later ones in the same
  // transaction, and those without one, move the old history into the log (or drop it).
  AsHistory& Rewrite(uint32_t record, VkAccelerationStructureKHR as, Transaction* txn,
                     const std::shared_ptr<const BuildSnapshot>& build) {
    Record& r = records_[record];
    if (!txn || txn->id_ == 0 || r.flipped_by == txn->id_) return RewriteInPlace(record, as, txn, build);
    // The other slot holds what undo no longer needs (a transaction over, or one that never flipped this record).
    const uint64_t version = ++version_counter_;
    AsHistory& h = r.slots[r.current ^ 1];
    h.span = r.slots[r.current].span;
    txn->entries_.push_back(Transaction::Entry{Transaction::Kind::kFlip, 0, as, version, r.version});
    r.current ^= 1;
    r.flipped_by = txn->id_;
    r.version = version;
    NoteRewritten(r.slots[r.current ^ 1].build.get(), build.get());
    ResetForRewrite(h, build);
    return h;
  }

  // A submission's undo log: a spare one (keeping the capacity an earlier submission gave it) or a new one; and
  // back when the submission is over (cleared by the caller, outside the lock: the old histories it releases
  // may hold the last references to captured bytes).
  std::unique_ptr<Transaction> TakeTransaction();
  void ReturnTransaction(std::unique_ptr<Transaction> txn);
  // Destroyed: its history ends; a new structure with the same handle value starts fresh.
  void Forget(VkAccelerationStructureKHR as);
  uint64_t NextGeneration() { return ++generation_counter_; }
  // How many times a bottom-level structure's contents were replaced by a build of another geometry layout
  // (SameGeometryLayout; a rebuild, a copy or a deserialization over it). A top level's trace (family traces)
  // walks the bottom levels its last build referenced only when this, or the structures, changed since.
  uint64_t bottom_layout_changes() const { return bottom_layout_changes_; }

  // Structures whose span overlaps `span` (other than `except`).
  template <typename F>
  void ForEachOverlapping(const MemorySpan& span, VkAccelerationStructureKHR except, F&& f) const;
  // Structures whose span overlaps the span of `record` (of structure as), without searching when no other
  // structure's span has come to overlap it since the last search found none (most structures own their
  // bytes: then nothing is searched at all).
  template <typename F>
  void ForEachOverlappingRecord(uint32_t record, VkAccelerationStructureKHR as, F&& f);
  // True when ForEachOverlappingRecord(record) would find nothing without searching.
  bool Alone(uint32_t record) const { return records_[record].alone_epoch == overlap_epoch_; }

  // Serialized bytes.
  bool has_blobs() const { return !blobs_.empty(); }
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

  std::size_t size() const { return index_.size(); }

  // What the store holds, and the most it held at once (the layer's footprint, footprint.h).
  struct Sizes {
    std::size_t records = 0, record_slots = 0, spans = 0, blobs = 0, query_slots = 0, spare_transactions = 0;
    std::size_t peak_records = 0, peak_blobs = 0, peak_query_slots = 0;
  };
  Sizes sizes() const {
    return Sizes{index_.size(), records_.size(), spans_.size(), blobs_.size(), slots_.size(),
                 spare_transactions_.size(), peak_records_, peak_blobs_, peak_query_slots_};
  }

  // Counters, readable without the lock.
  mutable std::atomic<uint64_t> ops_applied{0};
  mutable std::atomic<uint64_t> rules_skipped_unknown_history{0};  // history checks skipped: unknown history
  mutable std::atomic<uint64_t> structures_made_unknown{0};

 private:
  struct Record {
    Record() = default;
    Record(AsHistory history, uint64_t version_) : version(version_) { slots[0] = std::move(history); }
    AsHistory& history() { return slots[current]; }
    const AsHistory& history() const { return slots[current]; }

    // The history now (slots[current]) and, after a rewrite by a transaction still undoable, the one before it.
    AsHistory slots[2];
    uint8_t current = 0;
    uint64_t version = 0;
    // The transaction (Transaction::id_) whose undo may switch `current` back; 0: none.
    uint64_t flipped_by = 0;
    // No other structure's span overlapped this one's when overlap_epoch_ had this value (0: not known). Valid
    // while overlap_epoch_ keeps it: a span that comes to overlap another bumps the epoch, and removing spans
    // never makes new overlaps.
    uint64_t alone_epoch = 0;
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
  // Indexes record's span, and notes whether it overlaps another structure's.
  void Index(uint32_t record, VkAccelerationStructureKHR as);
  uint32_t Insert(VkAccelerationStructureKHR as, AsHistory history, uint64_t version);
  void Push(Transaction* txn, Transaction::Kind kind, uint64_t blob_id);
  AsHistory& RewriteInPlace(uint32_t record, VkAccelerationStructureKHR as, Transaction* txn,
                            const std::shared_ptr<const BuildSnapshot>& build);
  // Counts a bottom level's contents replaced by a build of another layout (before, after: their builds' snapshots).
  void NoteRewritten(const BuildSnapshot* before, const BuildSnapshot* after) {
    if (before == after || !before || !after) return;  // most rewrites keep their snapshot: one compare
    if (before->type == VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR && !SameGeometryLayout(*before, *after)) {
      ++bottom_layout_changes_;
    }
  }
  void ResetForRewrite(AsHistory& h, const std::shared_ptr<const BuildSnapshot>& build) {
    h.kind = HistoryKind::kNeverBuilt;
    h.unknown_reason = UnknownReason::kNone;
    // A structure rebuilt or updated every frame finds the snapshot it had two writes ago in the slot: no
    // reference count changes.
    if (h.build != build) h.build = build;
    h.clobbered.reset();
    h.generation = NextGeneration();
    h.serialization_size = 0;
    h.serialization_size_generation = 0;
    h.activity.reset();
  }

  mutable std::mutex mutex_;
  // Records by index (stable while the structure has one), found through index_; freed indices are reused.
  HandleIndex index_;
  std::vector<Record> records_;
  std::vector<uint32_t> free_records_;
  std::vector<std::unique_ptr<Transaction>> spare_transactions_;
  std::multimap<SpanKey, SpanEntry> spans_;
  uint64_t overlap_epoch_ = 1;
  uint64_t transaction_counter_ = 0;
  std::unordered_map<VkDeviceMemory, VkDeviceSize, HandleHash<VkDeviceMemory>> longest_span_;
  std::vector<SerializedBlob> blobs_;
  std::unordered_map<std::pair<VkQueryPool, uint32_t>, SlotRecord, SlotKeyHash> slots_;
  uint64_t generation_counter_ = 0;
  uint64_t bottom_layout_changes_ = 0;
  uint64_t version_counter_ = 0;
  uint64_t blob_counter_ = 0;
  std::size_t peak_records_ = 0, peak_blobs_ = 0, peak_query_slots_ = 0;  // Sizes
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

template <typename F>
void HistoryStore::ForEachOverlappingRecord(uint32_t record, VkAccelerationStructureKHR as, F&& f) {
  if (Alone(record)) return;
  bool any = false;
  ForEachOverlapping(records_[record].history().span, as, [&](VkAccelerationStructureKHR other) {
    any = true;
    f(other);
  });
  if (!any) records_[record].alone_epoch = overlap_epoch_;
}

}  // namespace asval
