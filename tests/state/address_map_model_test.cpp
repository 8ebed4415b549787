// DeviceAddressMap against a brute-force model: random inserts, erases and queries with a fixed seed.
#include "state/address_map.h"

#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <functional>
#include <optional>
#include <vector>

#include "fake_handles.h"

namespace asval {
namespace {

using test::FakeBuffer;
using test::Random;

// The obvious implementation: a list of (buffer, base, last) scanned in full.
class ModelMap {
 public:
  void Insert(VkDeviceAddress base, VkDeviceSize size, VkBuffer buffer) {
    Erase(buffer);
    if (size == 0 || size - 1 > ~VkDeviceAddress{0} - base) return;
    entries_.push_back({buffer, base, base + (size - 1)});
  }
  bool Erase(VkBuffer buffer) {
    const auto it = std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.buffer == buffer; });
    if (it == entries_.end()) return false;
    entries_.erase(it);
    return true;
  }
  // Buffers containing [addr, last], sorted by handle like the real map.
  std::vector<VkBuffer> Covering(VkDeviceAddress addr, VkDeviceAddress last) const {
    std::vector<VkBuffer> out;
    for (const Entry& e : entries_) {
      if (e.base <= addr && last <= e.last) out.push_back(e.buffer);
    }
    std::sort(out.begin(), out.end(), std::less<VkBuffer>{});
    return out;
  }
  std::size_t size() const { return entries_.size(); }

 private:
  struct Entry {
    VkBuffer buffer;
    VkDeviceAddress base;
    VkDeviceAddress last;
  };
  std::vector<Entry> entries_;
};

// Runs `ops` random operations on addresses base_offset + [0, span). Buffer ids come from a small pool so that
// handles get re-inserted (replaced) and erased while unknown.
void RunAgainstModel(std::uint64_t seed, VkDeviceAddress base_offset, std::uint64_t span, int ops) {
  Random random(seed);
  DeviceAddressMap map;
  ModelMap model;
  AddressHits hits;
  constexpr std::uint64_t kPool = 48;
  // The predicate stands for the caller's usage/binding checks: it rejects a third of the buffers.
  const auto accept = [](VkBuffer b) { return test::FakeId(b) % 3 != 0; };

  for (int op = 0; op < ops; ++op) {
    const std::uint64_t kind = random.Below(100);
    const VkBuffer buffer = FakeBuffer(random.Below(kPool));
    if (kind < 35) {
      const VkDeviceAddress base = base_offset + random.Below(span);
      // Mostly small ranges, some long ones (including past the end of the window, which may wrap).
      const VkDeviceSize size = random.Below(10) == 0 ? random.Below(span * 2) : random.Below(span / 16);
      const bool expect_stored = size != 0 && size - 1 <= ~VkDeviceAddress{0} - base;
      REQUIRE(map.Insert(base, size, buffer) == expect_stored);
      model.Insert(base, size, buffer);
    } else if (kind < 55) {
      REQUIRE(map.Erase(buffer) == model.Erase(buffer));
    } else if (kind < 80) {
      const VkDeviceAddress addr = base_offset + random.Below(span);
      map.FindContaining(addr, hits);
      std::vector<VkBuffer> got;
      for (const AddressHit& hit : hits) {
        got.push_back(hit.buffer);
        const auto range = map.RangeOf(hit.buffer);
        REQUIRE(range.has_value());
        REQUIRE(range->base == hit.base);
        REQUIRE(range->size == hit.size);
      }
      REQUIRE(got == model.Covering(addr, addr));
    } else {
      const VkDeviceAddress addr = base_offset + random.Below(span);
      const VkDeviceSize size = random.Below(span / 8);
      const VkDeviceAddress last = size == 0 ? addr : addr + (size - 1);
      const bool wraps = size != 0 && size - 1 > ~VkDeviceAddress{0} - addr;
      std::vector<VkBuffer> expected = wraps ? std::vector<VkBuffer>{} : model.Covering(addr, last);
      const auto any = map.FindCovering(addr, size);
      REQUIRE(any.has_value() == !expected.empty());
      if (any) REQUIRE(any->buffer == expected.front());
      expected.erase(std::remove_if(expected.begin(), expected.end(), [&](VkBuffer b) { return !accept(b); }),
                     expected.end());
      const auto filtered = map.FindCovering(addr, size, accept);
      REQUIRE(filtered.has_value() == !expected.empty());
      if (filtered) REQUIRE(filtered->buffer == expected.front());
    }
    REQUIRE(map.size() == model.size());
    REQUIRE(map.SegmentCount() <= 2 * model.size());
  }

  for (std::uint64_t id = 0; id < kPool; ++id) REQUIRE(map.Erase(FakeBuffer(id)) == model.Erase(FakeBuffer(id)));
  CHECK(map.SegmentCount() == 0);  // no boundary outlives the ranges that made it
}

TEST_CASE("DeviceAddressMap matches a brute-force model", "[state][address_map][model]") {
  SECTION("dense overlaps in a small window") { RunAgainstModel(0x5eed0001, 0x10000, 4096, 6000); }
  SECTION("window at the top of the 64-bit space") {
    RunAgainstModel(0x5eed0002, ~VkDeviceAddress{0} - 4095, 4096, 6000);
  }
  SECTION("window starting at address 0") { RunAgainstModel(0x5eed0003, 0, 2048, 4000); }
}

}  // namespace
}  // namespace asval
