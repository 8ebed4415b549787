#include "address_map.h"

#include <algorithm>
#include <functional>
#include <iterator>
#include <mutex>
#include <new>

namespace asval {
namespace {

constexpr VkDeviceAddress kMaxAddress = ~VkDeviceAddress{0};

// Inclusive last address of [base, base + size), or nullopt when the range is empty or wraps past 2^64.
std::optional<VkDeviceAddress> LastAddress(VkDeviceAddress base, VkDeviceSize size) {
  if (size == 0 || size - 1 > kMaxAddress - base) return std::nullopt;
  return base + (size - 1);
}

// Range sizes always fit: Insert only accepts size <= 2^64 - base with size a VkDeviceSize.
AddressHit MakeHit(VkBuffer buffer, VkDeviceAddress base, VkDeviceAddress last) {
  return AddressHit{buffer, base, last - base + 1};
}

}  // namespace

void AddressHits::push_back(const AddressHit& hit) {
  if (size_ < kInlineCapacity) {
    inline_[size_++] = hit;
    return;
  }
  if (size_ == kInlineCapacity) spill_.assign(inline_.begin(), inline_.end());
  spill_.push_back(hit);
  ++size_;
}

bool DeviceAddressMap::Insert(VkDeviceAddress base, VkDeviceSize size, VkBuffer buffer) {
  std::unique_lock lock(mutex_);
  stamp_.Bump();  // under the lock: a reader that sees the new count looks the map up after this change
  EraseLocked(buffer);
  const std::optional<VkDeviceAddress> last = LastAddress(base, size);
  if (buffer == VK_NULL_HANDLE || !last) return false;

  const Range range{base, *last};
  try {
    ranges_.emplace(buffer, range);
    // Split the end first or second does not matter: std::map insertions keep other iterators valid.
    const auto first = SplitAt(base);
    const auto stop = *last == kMaxAddress ? segments_.end() : SplitAt(*last + 1);
    const Entry entry{buffer, range};
    for (auto it = first; it != stop; ++it) {
      EntryList& list = it->second;
      const auto pos = std::lower_bound(list.begin(), list.end(), buffer, [](const Entry& e, VkBuffer b) {
        return std::less<VkBuffer>{}(e.buffer, b);
      });
      list.insert(pos, entry);
    }
  } catch (const std::bad_alloc&) {
    // Half inserted: taken out of every list again (erasing allocates nothing), so that the map holds the buffer
    // nowhere rather than in part of its range; boundaries split for it stay, separating equal lists (harmless).
    for (auto& [at, list] : segments_) {
      list.erase(std::remove_if(list.begin(), list.end(), [buffer](const Entry& e) { return e.buffer == buffer; }),
                 list.end());
    }
    ranges_.erase(buffer);
    throw;
  }
  // New boundaries separate lists that differ by `buffer`, so no merge is needed here.
  return true;
}

bool DeviceAddressMap::Erase(VkBuffer buffer) {
  std::unique_lock lock(mutex_);
  return EraseLocked(buffer);
}

bool DeviceAddressMap::Erase(VkDeviceAddress base, VkBuffer buffer) {
  std::unique_lock lock(mutex_);
  const auto it = ranges_.find(buffer);
  if (it == ranges_.end() || it->second.base != base) return false;
  return EraseLocked(buffer);
}

bool DeviceAddressMap::EraseLocked(VkBuffer buffer) {
  const auto found = ranges_.find(buffer);
  if (found == ranges_.end()) return false;
  stamp_.Bump();
  const Range range = found->second;
  ranges_.erase(found);

  // Both boundaries exist: Insert created them and merges only remove boundaries between equal lists,
  // which a boundary of a live range never is.
  const auto first = segments_.find(range.base);
  const auto stop = range.last == kMaxAddress ? segments_.end() : segments_.find(range.last + 1);
  for (auto it = first; it != stop; ++it) {
    EntryList& list = it->second;
    list.erase(std::find_if(list.begin(), list.end(), [buffer](const Entry& e) { return e.buffer == buffer; }));
  }
  // Interior boundaries still separate different lists (both sides lost the same buffer); only the two
  // outer ones can have become redundant. Merge the later one first: erasing it leaves `first` valid.
  if (stop != segments_.end()) MergeIfRedundant(stop);
  MergeIfRedundant(first);
  return true;
}

DeviceAddressMap::SegmentMap::iterator DeviceAddressMap::SplitAt(VkDeviceAddress addr) {
  const auto next = segments_.upper_bound(addr);
  if (next == segments_.begin()) {
    // Below every segment: the new segment starts a gap until the next boundary.
    return segments_.emplace_hint(next, addr, EntryList{});
  }
  const auto containing = std::prev(next);
  if (containing->first == addr) return containing;
  return segments_.emplace_hint(next, addr, containing->second);
}

void DeviceAddressMap::MergeIfRedundant(SegmentMap::iterator it) {
  static const EntryList kNothing;  // what lies below the first segment
  const EntryList& before = it == segments_.begin() ? kNothing : std::prev(it)->second;
  const EntryList& here = it->second;
  const bool same = std::equal(before.begin(), before.end(), here.begin(), here.end(),
                               [](const Entry& a, const Entry& b) { return a.buffer == b.buffer; });
  if (same) segments_.erase(it);
}

const DeviceAddressMap::EntryList* DeviceAddressMap::SegmentContaining(VkDeviceAddress addr) const {
  auto it = segments_.upper_bound(addr);
  if (it == segments_.begin()) return nullptr;
  return &std::prev(it)->second;
}

std::size_t DeviceAddressMap::FindContaining(VkDeviceAddress addr, AddressHits& out) const {
  out.clear();
  std::shared_lock lock(mutex_);
  if (const EntryList* list = SegmentContaining(addr)) {
    for (const Entry& e : *list) out.push_back(MakeHit(e.buffer, e.range.base, e.range.last));
  }
  return out.size();
}

std::optional<AddressHit> DeviceAddressMap::FindCoveringImpl(VkDeviceAddress addr, VkDeviceSize size,
                                                             BufferFilter filter, const void* context) const {
  const std::optional<VkDeviceAddress> last = size == 0 ? std::optional<VkDeviceAddress>(addr)
                                                        : LastAddress(addr, size);
  if (!last) return std::nullopt;
  std::shared_lock lock(mutex_);
  const EntryList* list = SegmentContaining(addr);
  if (list == nullptr) return std::nullopt;
  // Every entry of the segment starts at or below addr; it covers the query iff it also reaches `last`.
  for (const Entry& e : *list) {
    if (e.range.last >= *last && (filter == nullptr || filter(context, e.buffer))) {
      return MakeHit(e.buffer, e.range.base, e.range.last);
    }
  }
  return std::nullopt;
}

std::optional<AddressHit> DeviceAddressMap::RangeOf(VkBuffer buffer) const {
  std::shared_lock lock(mutex_);
  const auto it = ranges_.find(buffer);
  if (it == ranges_.end()) return std::nullopt;
  return MakeHit(buffer, it->second.base, it->second.last);
}

std::size_t DeviceAddressMap::size() const {
  std::shared_lock lock(mutex_);
  return ranges_.size();
}

void DeviceAddressMap::Clear() {
  std::unique_lock lock(mutex_);
  segments_.clear();
  ranges_.clear();
  stamp_.Bump();
}

std::size_t DeviceAddressMap::SegmentCount() const {
  std::shared_lock lock(mutex_);
  return segments_.size();
}

}  // namespace asval
