#include "history.h"

#include <algorithm>

#define XXH_INLINE_ALL
#include <xxhash.h>

namespace asval {

const char* UnknownReasonText(UnknownReason reason) {
  switch (reason) {
    case UnknownReason::kNone: return "";
    case UnknownReason::kDeserializedUnknownBytes:
      return "deserialized from bytes the layer did not see serialized (or saw modified since)";
    case UnknownReason::kCopiedFromUnknown: return "copied from a structure whose history is unknown";
    case UnknownReason::kDeserializedDeviceBytes:
      return "deserialized from device memory whose bytes the layer could not verify (not captured, changed since "
             "they were serialized, or not yet seen complete)";
    case UnknownReason::kLostOperations:
      return "written by a command buffer the layer did not see recorded, or whose operations it could not record";
    case UnknownReason::kUnreadableBuild: return "built by an invalid build whose geometries could not be read";
    case UnknownReason::kStaleHandle:
      return "written by a command recorded with a structure destroyed since, whose handle this structure reuses";
  }
  return "";
}

uint64_t HashBytes(const void* data, std::size_t size) { return XXH3_64bits(data, size); }

AsHistory HistoryStore::Get(VkAccelerationStructureKHR as) const {
  if (const AsHistory* found = Find(as)) return *found;
  return AsHistory{};
}

void HistoryStore::Index(uint32_t record, VkAccelerationStructureKHR as) {
  Record& r = records_[record];
  const MemorySpan& span = r.history().span;
  r.alone_epoch = 0;
  if (span.memory == VK_NULL_HANDLE || span.begin >= span.end) return;
  bool overlaps = false;
  ForEachOverlapping(span, as, [&](VkAccelerationStructureKHR) { overlaps = true; });
  // A new overlap makes every structure's "alone" note stale: they search again at their next write.
  if (overlaps) {
    ++overlap_epoch_;
  } else {
    r.alone_epoch = overlap_epoch_;
  }
  spans_.emplace(SpanKey{span.memory, span.begin}, SpanEntry{as, span.end});
  VkDeviceSize& longest = longest_span_[span.memory];
  longest = std::max(longest, span.end - span.begin);
}

void HistoryStore::Unindex(VkAccelerationStructureKHR as, const MemorySpan& span) {
  if (span.memory == VK_NULL_HANDLE || span.begin >= span.end) return;
  auto [first, last] = spans_.equal_range(SpanKey{span.memory, span.begin});
  for (auto it = first; it != last; ++it) {
    if (it->second.as == as) {
      spans_.erase(it);
      return;
    }
  }
  // longest_span_ stays an upper bound; it only widens the window a query scans.
}

uint32_t HistoryStore::Insert(VkAccelerationStructureKHR as, AsHistory history, uint64_t version) {
  uint32_t record;
  if (!free_records_.empty()) {
    record = free_records_.back();
    free_records_.pop_back();
    records_[record] = Record(std::move(history), version);
  } else {
    record = static_cast<uint32_t>(records_.size());
    records_.emplace_back(std::move(history), version);
  }
  index_.Insert(reinterpret_cast<uint64_t>(as), record);
  peak_records_ = std::max(peak_records_, index_.size());
  Index(record, as);
  return record;
}

bool SameGeometryLayout(const BuildSnapshot& a, const BuildSnapshot& b) {
  if (a.geometries.size() != b.geometries.size()) return false;
  for (std::size_t g = 0; g < a.geometries.size(); ++g) {
    if (a.geometries[g].type != b.geometries[g].type) return false;
  }
  return true;
}

uint32_t HistoryStore::Set(VkAccelerationStructureKHR as, AsHistory history, Transaction* txn) {
  if (as == VK_NULL_HANDLE) return kNoRecord;  // not a structure: nothing can ask for its record
  const uint32_t record = RecordOf(as);
  if (record != kNoRecord) {
    SetAt(record, as, std::move(history), txn);
    return record;
  }
  const uint64_t version = ++version_counter_;
  if (txn) {
    txn->entries_.reserve(txn->entries_.size() + 1);  // so that the entry never names a change that failed
    txn->histories_.emplace_back(as, version, 0, false, AsHistory{});
    txn->entries_.push_back(Transaction::Entry{Transaction::Kind::kHistory,
                                               static_cast<uint32_t>(txn->histories_.size() - 1)});
  }
  return Insert(as, std::move(history), version);
}

void HistoryStore::SetAt(uint32_t record, VkAccelerationStructureKHR as, AsHistory history, Transaction* txn) {
  Record& r = records_[record];
  const uint64_t version = ++version_counter_;
  const MemorySpan& old_span = r.history().span;
  const bool moved = old_span.memory != history.span.memory || old_span.begin != history.span.begin ||
                     old_span.end != history.span.end;
  if (moved) Unindex(as, old_span);
  NoteRewritten(r.history().build.get(), history.build.get());
  if (txn) {
    txn->entries_.reserve(txn->entries_.size() + 1);  // so that the entry never names a change that failed
    txn->histories_.emplace_back(as, version, r.version, true, std::move(r.history()));
    txn->entries_.push_back(Transaction::Entry{Transaction::Kind::kHistory,
                                               static_cast<uint32_t>(txn->histories_.size() - 1)});
  }
  r.history() = std::move(history);
  r.version = version;
  if (moved) Index(record, as);
}

AsHistory& HistoryStore::RewriteInPlace(uint32_t record, VkAccelerationStructureKHR as, Transaction* txn,
                                         const std::shared_ptr<const BuildSnapshot>& build) {
  Record& r = records_[record];
  const uint64_t version = ++version_counter_;
  AsHistory& h = r.history();
  NoteRewritten(h.build.get(), build.get());
  if (txn) {
    txn->entries_.reserve(txn->entries_.size() + 1);  // so that the entry never names a change that failed
    txn->histories_.emplace_back(as, version, r.version, true, std::move(h));  // leaves the span as it was
    txn->entries_.push_back(Transaction::Entry{Transaction::Kind::kHistory,
                                               static_cast<uint32_t>(txn->histories_.size() - 1)});
  }
  r.version = version;
  ResetForRewrite(h, build);
  return h;
}

std::unique_ptr<Transaction> HistoryStore::TakeTransaction() {
  if (spare_transactions_.empty()) {
    auto txn = std::make_unique<Transaction>();
    txn->id_ = ++transaction_counter_;
    return txn;
  }
  std::unique_ptr<Transaction> txn = std::move(spare_transactions_.back());
  spare_transactions_.pop_back();
  txn->id_ = ++transaction_counter_;
  return txn;
}

void HistoryStore::ReturnTransaction(std::unique_ptr<Transaction> txn) {
  // A few are enough: more are in use at once only while app callbacks submit from within submissions.
  if (spare_transactions_.size() < 4) spare_transactions_.push_back(std::move(txn));
}

void HistoryStore::Forget(VkAccelerationStructureKHR as) {
  const uint32_t record = RecordOf(as);
  if (record == kNoRecord) return;
  Unindex(as, records_[record].history().span);
  index_.Erase(reinterpret_cast<uint64_t>(as));
  records_[record] = Record{};  // releases its snapshot and activity now
  free_records_.push_back(record);
}

void HistoryStore::Push(Transaction* txn, Transaction::Kind kind, uint64_t blob_id) {
  if (!txn) return;
  txn->entries_.reserve(txn->entries_.size() + 1);  // so that the entry never names a change that failed
  txn->blobs_.push_back(blob_id);
  txn->entries_.push_back(Transaction::Entry{kind, static_cast<uint32_t>(txn->blobs_.size() - 1)});
}

uint64_t HistoryStore::AddBlob(SerializedBlob blob, Transaction* txn) {
  // Drop blobs that can no longer restore anything, so that a long run does not accumulate them.
  if (blobs_.size() >= 64) {
    blobs_.erase(std::remove_if(blobs_.begin(), blobs_.end(), [](const SerializedBlob& b) { return !b.valid; }),
                 blobs_.end());
  }
  blob.id = ++blob_counter_;
  blob.valid = true;
  Push(txn, Transaction::Kind::kBlobAdded, blob.id);
  blobs_.push_back(std::move(blob));
  peak_blobs_ = std::max(peak_blobs_, blobs_.size());
  return blob_counter_;
}

const SerializedBlob* HistoryStore::FindHostBlob(const void* host_address) const {
  if (!host_address) return nullptr;
  for (auto it = blobs_.rbegin(); it != blobs_.rend(); ++it) {
    if (it->valid && it->host_address == host_address) return &*it;
  }
  return nullptr;
}

const SerializedBlob* HistoryStore::FindDeviceBlob(const MemorySpan& span) const {
  if (span.memory == VK_NULL_HANDLE) return nullptr;
  for (auto it = blobs_.rbegin(); it != blobs_.rend(); ++it) {
    if (it->valid && it->span.memory == span.memory && it->span.begin == span.begin) return &*it;
  }
  return nullptr;
}

const SerializedBlob* HistoryStore::FindDeviceBlobAt(VkDeviceAddress address) const {
  if (address == 0) return nullptr;
  for (auto it = blobs_.rbegin(); it != blobs_.rend(); ++it) {
    if (it->valid && it->device_address == address) return &*it;
  }
  return nullptr;
}

void HistoryStore::InvalidateBlobsOverlapping(const MemorySpan& span, Transaction* txn) {
  for (SerializedBlob& blob : blobs_) {
    if (!blob.valid || !Overlaps(blob.span, span)) continue;
    blob.valid = false;
    Push(txn, Transaction::Kind::kBlobInvalidated, blob.id);
  }
}

void HistoryStore::InvalidateHostBlob(const void* host_address, Transaction* txn) {
  for (SerializedBlob& blob : blobs_) {
    if (!blob.valid || blob.host_address != host_address) continue;
    blob.valid = false;
    Push(txn, Transaction::Kind::kBlobInvalidated, blob.id);
  }
}

void HistoryStore::InvalidateAllBlobs(Transaction* txn) {
  for (SerializedBlob& blob : blobs_) {
    if (!blob.valid) continue;
    blob.valid = false;
    Push(txn, Transaction::Kind::kBlobInvalidated, blob.id);
  }
}

void HistoryStore::SetSlot(VkQueryPool pool, uint32_t query, const QuerySlot& slot, Transaction* txn) {
  const auto key = std::make_pair(pool, query);
  const uint64_t version = ++version_counter_;
  auto it = slots_.find(key);
  if (txn) {
    txn->entries_.reserve(txn->entries_.size() + 1);  // so that the entry never names a change that failed
    Transaction::SlotChange change{key, version, 0, std::nullopt};
    if (it != slots_.end()) {
      change.old_slot = it->second.slot;
      change.old_version = it->second.version;
    }
    txn->slots_.push_back(std::move(change));
    txn->entries_.push_back(
        Transaction::Entry{Transaction::Kind::kSlot, static_cast<uint32_t>(txn->slots_.size() - 1)});
  }
  slots_[key] = SlotRecord{slot, version};
  peak_query_slots_ = std::max(peak_query_slots_, slots_.size());
}

const QuerySlot* HistoryStore::FindSlot(VkQueryPool pool, uint32_t query) const {
  const auto it = slots_.find(std::make_pair(pool, query));
  return it == slots_.end() ? nullptr : &it->second.slot;
}

void HistoryStore::ForgetPool(VkQueryPool pool) {
  for (auto it = slots_.begin(); it != slots_.end();) {
    it = it->first.first == pool ? slots_.erase(it) : std::next(it);
  }
}

void HistoryStore::ForgetMemory(VkDeviceMemory memory) {
  blobs_.erase(std::remove_if(blobs_.begin(), blobs_.end(),
                              [memory](const SerializedBlob& b) { return b.span.memory == memory; }),
               blobs_.end());
  auto it = spans_.lower_bound(SpanKey{memory, 0});
  while (it != spans_.end() && it->first.memory == memory) {
    if (const uint32_t record = RecordOf(it->second.as); record != kNoRecord) {
      // Both slots: an undo that switches back must not index bytes that are gone.
      records_[record].slots[0].span = MemorySpan{};
      records_[record].slots[1].span = MemorySpan{};
    }
    it = spans_.erase(it);
  }
  longest_span_.erase(memory);
}

void HistoryStore::Undo(Transaction& txn) {
  for (auto e = txn.entries_.rbegin(); e != txn.entries_.rend(); ++e) {
    switch (e->kind) {
      case Transaction::Kind::kHistory: {
        Transaction::HistoryChange& change = txn.histories_[e->at];
        const uint32_t record = RecordOf(change.as);
        if (record == kNoRecord || records_[record].version != change.version) break;  // changed since: keep it
        if (change.existed) {
          SetAt(record, change.as, std::move(change.old_history), nullptr);
          // The version it had before, so that an earlier entry of this transaction for it still matches.
          records_[record].version = change.old_version;
        } else {
          Forget(change.as);
        }
        break;
      }
      case Transaction::Kind::kFlip: {
        const Transaction::Entry& flip = *e;
        const uint32_t record = RecordOf(flip.as);
        if (record == kNoRecord || records_[record].version != flip.version) break;  // changed since: keep it
        Record& r = records_[record];
        const MemorySpan& now = r.history().span;
        const MemorySpan& before = r.slots[r.current ^ 1].span;
        const bool moved = now.memory != before.memory || now.begin != before.begin || now.end != before.end;
        if (moved) Unindex(flip.as, now);
        r.current ^= 1;
        r.version = flip.old_version;
        r.flipped_by = 0;
        if (moved) Index(record, flip.as);
        break;
      }
      case Transaction::Kind::kBlobAdded: {
        const uint64_t id = txn.blobs_[e->at];
        blobs_.erase(std::remove_if(blobs_.begin(), blobs_.end(), [&](const SerializedBlob& b) { return b.id == id; }),
                     blobs_.end());
        break;
      }
      case Transaction::Kind::kBlobInvalidated:
        for (SerializedBlob& blob : blobs_) {
          if (blob.id == txn.blobs_[e->at]) blob.valid = true;
        }
        break;
      case Transaction::Kind::kSlot: {
        const Transaction::SlotChange& change = txn.slots_[e->at];
        auto it = slots_.find(change.key);
        if (it == slots_.end() || it->second.version != change.version) break;
        if (change.old_slot) {
          it->second = SlotRecord{*change.old_slot, change.old_version};
        } else {
          slots_.erase(it);
        }
        break;
      }
    }
  }
  txn.Clear();
}

}  // namespace asval
