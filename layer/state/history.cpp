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
  }
  return "";
}

uint64_t HashBytes(const void* data, std::size_t size) { return XXH3_64bits(data, size); }

AsHistory HistoryStore::Get(VkAccelerationStructureKHR as) const {
  if (const AsHistory* found = Find(as)) return *found;
  return AsHistory{};
}

const AsHistory* HistoryStore::Find(VkAccelerationStructureKHR as) const {
  const auto it = histories_.find(as);
  return it == histories_.end() ? nullptr : &it->second.history;
}

void HistoryStore::Index(VkAccelerationStructureKHR as, const MemorySpan& span) {
  if (span.memory == VK_NULL_HANDLE || span.begin >= span.end) return;
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

void HistoryStore::Set(VkAccelerationStructureKHR as, AsHistory history, Transaction* txn) {
  auto it = histories_.find(as);
  const uint64_t version = ++version_counter_;
  if (txn) {
    Transaction::Entry entry{Transaction::Kind::kHistory};
    entry.as = as;
    if (it != histories_.end()) {
      entry.old_history = it->second.history;
      entry.old_version = it->second.version;
    }
    entry.version = version;
    txn->entries_.push_back(std::move(entry));
  }
  if (it == histories_.end()) {
    Index(as, history.span);
    histories_.emplace(as, Record{std::move(history), version});
    return;
  }
  const MemorySpan& old_span = it->second.history.span;
  if (old_span.memory != history.span.memory || old_span.begin != history.span.begin ||
      old_span.end != history.span.end) {
    Unindex(as, old_span);
    Index(as, history.span);
  }
  it->second.history = std::move(history);
  it->second.version = version;
}

void HistoryStore::Forget(VkAccelerationStructureKHR as) {
  auto it = histories_.find(as);
  if (it == histories_.end()) return;
  Unindex(as, it->second.history.span);
  histories_.erase(it);
}

uint64_t HistoryStore::AddBlob(SerializedBlob blob, Transaction* txn) {
  // Drop blobs that can no longer restore anything, so that a long run does not accumulate them.
  if (blobs_.size() >= 64) {
    blobs_.erase(std::remove_if(blobs_.begin(), blobs_.end(), [](const SerializedBlob& b) { return !b.valid; }),
                 blobs_.end());
  }
  blob.id = ++blob_counter_;
  blob.valid = true;
  if (txn) {
    Transaction::Entry entry{Transaction::Kind::kBlobAdded};
    entry.blob_id = blob.id;
    txn->entries_.push_back(std::move(entry));
  }
  blobs_.push_back(std::move(blob));
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
    if (txn) {
      Transaction::Entry entry{Transaction::Kind::kBlobInvalidated};
      entry.blob_id = blob.id;
      txn->entries_.push_back(std::move(entry));
    }
  }
}

void HistoryStore::InvalidateHostBlob(const void* host_address, Transaction* txn) {
  for (SerializedBlob& blob : blobs_) {
    if (!blob.valid || blob.host_address != host_address) continue;
    blob.valid = false;
    if (txn) {
      Transaction::Entry entry{Transaction::Kind::kBlobInvalidated};
      entry.blob_id = blob.id;
      txn->entries_.push_back(std::move(entry));
    }
  }
}

void HistoryStore::InvalidateAllBlobs(Transaction* txn) {
  for (SerializedBlob& blob : blobs_) {
    if (!blob.valid) continue;
    blob.valid = false;
    if (txn) {
      Transaction::Entry entry{Transaction::Kind::kBlobInvalidated};
      entry.blob_id = blob.id;
      txn->entries_.push_back(std::move(entry));
    }
  }
}

void HistoryStore::SetSlot(VkQueryPool pool, uint32_t query, const QuerySlot& slot, Transaction* txn) {
  const auto key = std::make_pair(pool, query);
  const uint64_t version = ++version_counter_;
  auto it = slots_.find(key);
  if (txn) {
    Transaction::Entry entry{Transaction::Kind::kSlot};
    entry.slot_key = key;
    if (it != slots_.end()) {
      entry.old_slot = it->second.slot;
      entry.old_version = it->second.version;
    }
    entry.version = version;
    txn->entries_.push_back(std::move(entry));
  }
  slots_[key] = SlotRecord{slot, version};
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
    if (auto h = histories_.find(it->second.as); h != histories_.end()) h->second.history.span = MemorySpan{};
    it = spans_.erase(it);
  }
  longest_span_.erase(memory);
}

void HistoryStore::Undo(Transaction& txn) {
  for (auto e = txn.entries_.rbegin(); e != txn.entries_.rend(); ++e) {
    switch (e->kind) {
      case Transaction::Kind::kHistory: {
        auto it = histories_.find(e->as);
        if (it == histories_.end() || it->second.version != e->version) break;  // changed since: keep the newer
        if (e->old_history) {
          AsHistory old = std::move(*e->old_history);
          Set(e->as, std::move(old), nullptr);
          // The version it had before, so that an earlier entry of this transaction for it still matches.
          histories_.find(e->as)->second.version = e->old_version;
        } else {
          Forget(e->as);
        }
        break;
      }
      case Transaction::Kind::kBlobAdded:
        blobs_.erase(std::remove_if(blobs_.begin(), blobs_.end(),
                                    [&](const SerializedBlob& b) { return b.id == e->blob_id; }),
                     blobs_.end());
        break;
      case Transaction::Kind::kBlobInvalidated:
        for (SerializedBlob& blob : blobs_) {
          if (blob.id == e->blob_id) blob.valid = true;
        }
        break;
      case Transaction::Kind::kSlot: {
        auto it = slots_.find(e->slot_key);
        if (it == slots_.end() || it->second.version != e->version) break;
        if (e->old_slot) {
          it->second = SlotRecord{*e->old_slot, e->old_version};
        } else {
          slots_.erase(it);
        }
        break;
      }
    }
  }
  txn.entries_.clear();
}

}  // namespace asval
