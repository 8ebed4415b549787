// Device address -> VkBuffer lookups for one VkDevice.
//
// Build inputs, scratch and AS storage are given to the layer as raw VkDeviceAddress values; the checks
// need the buffer(s) behind an address. Several live buffers may cover the same bytes (aliasing on one
// VkDeviceMemory, a whole-allocation buffer plus sub-allocated buffers inside it, address reuse after a
// destroy), so every query can have several answers.
//
// Structure (why not an augmented tree): the address space is cut into elementary segments at every range
// boundary, kept in a std::map keyed by segment start. Each segment holds the small, sorted list of the
// buffers that cover all of it. A query is one map descent plus a scan of that list: O(log S + k) with S <= 2n
// segments for n buffers and k the buffers that contain the address — exactly the worst-case bound the checks
// want, with no window to scan back over. An augmented interval tree (keyed by base, subtree max end) costs
// O(k log n) for the same stabbing query and needs a hand-written balanced tree. The price of segments is on
// the write side: Insert/Erase touch every segment inside the range, and memory is the sum of the list sizes,
// O(n * nesting depth). Real programs nest shallowly (a whole-allocation buffer over its sub-allocations:
// depth 2), and reads (every build/copy/trace command) far outnumber writes (bind/destroy).
//
// Ranges are stored as [base, last] with an inclusive last address, so a buffer that ends exactly at 2^64
// is representable and no expression computes base + size.
//
// Thread safety: every member is safe to call concurrently. Queries take a shared lock, Insert/Erase/Clear an
// exclusive one. The FindCovering predicate runs under the shared lock: it may lock other objects (e.g. a
// buffer-state shard, for reading), but must never call a writer of this map.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <shared_mutex>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "change_stamp.h"

#include "concurrent_map.h"

namespace asval {

// One buffer whose address range matched a query.
struct AddressHit {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceAddress base = 0;
  VkDeviceSize size = 0;
};

// Result list of FindContaining. The first kInlineCapacity hits live inside the object, so a caller that
// keeps one on its stack (or reuses one) allocates nothing in the common case; more hits move to the heap.
class AddressHits {
 public:
  static constexpr std::size_t kInlineCapacity = 4;

  void clear() noexcept {
    size_ = 0;
    spill_.clear();  // keeps its capacity for the next reuse
  }
  void push_back(const AddressHit& hit);

  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  const AddressHit* begin() const noexcept { return data(); }
  const AddressHit* end() const noexcept { return data() + size_; }
  const AddressHit& operator[](std::size_t i) const noexcept { return data()[i]; }

 private:
  const AddressHit* data() const noexcept { return size_ > kInlineCapacity ? spill_.data() : inline_.data(); }

  std::array<AddressHit, kInlineCapacity> inline_{};
  std::vector<AddressHit> spill_;  // holds all hits once there are more than kInlineCapacity
  std::size_t size_ = 0;
};

class DeviceAddressMap {
 public:
  DeviceAddressMap() = default;
  DeviceAddressMap(const DeviceAddressMap&) = delete;
  DeviceAddressMap& operator=(const DeviceAddressMap&) = delete;

  // Records that `buffer` covers [base, base + size). A buffer has one address range: a second Insert of the
  // same handle replaces the first (the handle was recycled, or a destroy was missed). Returns false and
  // stores nothing for a null handle, size 0 (covers no address) or a range that would wrap past 2^64;
  // the buffer's previous range, if any, is dropped in that case too.
  bool Insert(VkDeviceAddress base, VkDeviceSize size, VkBuffer buffer);

  // Forgets the buffer's range. Returns false for a buffer that is not in the map.
  bool Erase(VkBuffer buffer);
  // Same, but only if the buffer's range starts at `base` (guards against erasing a re-inserted handle).
  bool Erase(VkDeviceAddress base, VkBuffer buffer);

  // Every buffer whose range contains addr, in handle order. Clears `out` first; returns out.size().
  std::size_t FindContaining(VkDeviceAddress addr, AddressHits& out) const;

  // A buffer whose range contains all of [addr, addr + size) and for which pred(VkBuffer) is true; the
  // first such in handle order. size 0 asks for a buffer containing addr. A range that wraps past 2^64
  // has no answer.
  template <typename Pred>
  std::optional<AddressHit> FindCovering(VkDeviceAddress addr, VkDeviceSize size, Pred&& pred) const {
    using PredType = std::remove_reference_t<Pred>;
    const auto call = [](const void* context, VkBuffer buffer) -> bool {
      return (*static_cast<PredType*>(const_cast<void*>(context)))(buffer);
    };
    return FindCoveringImpl(addr, size, call, std::addressof(pred));
  }
  std::optional<AddressHit> FindCovering(VkDeviceAddress addr, VkDeviceSize size) const {
    return FindCoveringImpl(addr, size, nullptr, nullptr);
  }

  // The range recorded for a buffer.
  std::optional<AddressHit> RangeOf(VkBuffer buffer) const;

  std::size_t size() const;  // buffers in the map
  bool empty() const { return size() == 0; }
  void Clear();
  // Changes so far (every Insert, Erase and Clear that changed something): equal stamps, no change between.
  StampValue stamp() const { return stamp_.Read(); }

  // Number of elementary segments; at most 2 * size(). For tests and diagnostics.
  std::size_t SegmentCount() const;

 private:
  struct Range {
    VkDeviceAddress base;
    VkDeviceAddress last;  // inclusive
  };
  struct Entry {
    VkBuffer buffer;
    Range range;
  };
  // Buffers covering one segment, sorted by handle so that two lists compare equal iff they hold the same set.
  using EntryList = std::vector<Entry>;
  // Segment start -> covering buffers. A segment ends where the next key starts (or at 2^64 - 1 for the
  // last key); gaps are segments with an empty list. No two neighbouring segments hold equal lists.
  using SegmentMap = std::map<VkDeviceAddress, EntryList>;
  using BufferFilter = bool (*)(const void* context, VkBuffer buffer);

  std::optional<AddressHit> FindCoveringImpl(VkDeviceAddress addr, VkDeviceSize size, BufferFilter filter,
                                             const void* context) const;
  // Returns the segment starting at addr, splitting the one that contains it if needed.
  SegmentMap::iterator SplitAt(VkDeviceAddress addr);
  // Removes the boundary at `it` when the segment before it holds the same buffers.
  void MergeIfRedundant(SegmentMap::iterator it);
  // The buffer's range removal, under an exclusive lock already held.
  bool EraseLocked(VkBuffer buffer);
  // Segment containing addr, or nullptr when addr is below every segment.
  const EntryList* SegmentContaining(VkDeviceAddress addr) const;

  mutable std::shared_mutex mutex_;
  SegmentMap segments_;
  std::unordered_map<VkBuffer, Range, HandleHash<VkBuffer>> ranges_;
  ChangeStamp stamp_;
};

}  // namespace asval
