#include "state/address_map.h"

#include <catch2/catch_test_macros.hpp>

#include <atomic>
#include <thread>
#include <vector>

#include "fake_handles.h"

namespace asval {
namespace {

using test::FakeBuffer;
constexpr VkDeviceAddress kTop = ~VkDeviceAddress{0};

std::vector<VkBuffer> Buffers(const AddressHits& hits) {
  std::vector<VkBuffer> out;
  for (const AddressHit& hit : hits) out.push_back(hit.buffer);
  return out;
}

std::vector<VkBuffer> Containing(const DeviceAddressMap& map, VkDeviceAddress addr) {
  AddressHits hits;
  map.FindContaining(addr, hits);
  return Buffers(hits);
}

TEST_CASE("DeviceAddressMap: one buffer, its edges", "[state][address_map]") {
  DeviceAddressMap map;
  const VkBuffer a = FakeBuffer(1);
  CHECK(Containing(map, 0x1000).empty());
  REQUIRE(map.Insert(0x1000, 0x100, a));

  CHECK(Containing(map, 0x0fff).empty());
  CHECK(Containing(map, 0x1000) == std::vector<VkBuffer>{a});
  CHECK(Containing(map, 0x10ff) == std::vector<VkBuffer>{a});
  CHECK(Containing(map, 0x1100).empty());

  const auto whole = map.FindCovering(0x1000, 0x100);
  REQUIRE(whole.has_value());
  CHECK(whole->buffer == a);
  CHECK(whole->base == 0x1000);
  CHECK(whole->size == 0x100);
  CHECK(map.FindCovering(0x10f0, 0x10).has_value());
  CHECK_FALSE(map.FindCovering(0x10f0, 0x11).has_value());  // one byte past the end
  CHECK_FALSE(map.FindCovering(0x0fff, 0x2).has_value());   // one byte before the start
  CHECK(map.FindCovering(0x10ff, 0).has_value());           // size 0: a buffer containing the address
  CHECK_FALSE(map.FindCovering(0x1100, 0).has_value());
  CHECK(map.SegmentCount() == 2);
}

TEST_CASE("DeviceAddressMap: rejected inserts and unknown erases", "[state][address_map]") {
  DeviceAddressMap map;
  CHECK_FALSE(map.Insert(0x1000, 0, FakeBuffer(1)));             // covers no address
  CHECK_FALSE(map.Insert(0x1000, 0x10, VK_NULL_HANDLE));
  CHECK_FALSE(map.Insert(kTop - 0xf, 0x11, FakeBuffer(2)));      // would wrap past 2^64
  CHECK_FALSE(map.Insert(2, kTop, FakeBuffer(3)));               // would end at 2^64 + 1
  CHECK(map.empty());
  CHECK(map.SegmentCount() == 0);
  CHECK(Containing(map, 0x1000).empty());

  CHECK_FALSE(map.Erase(FakeBuffer(1)));
  CHECK_FALSE(map.Erase(0x1000, FakeBuffer(1)));
  REQUIRE(map.Insert(0x2000, 0x10, FakeBuffer(4)));
  CHECK_FALSE(map.Erase(0x2008, FakeBuffer(4)));  // wrong base: left in place
  CHECK(map.RangeOf(FakeBuffer(4)).has_value());
  CHECK(map.Erase(0x2000, FakeBuffer(4)));
  CHECK_FALSE(map.Erase(FakeBuffer(4)));
  CHECK(map.SegmentCount() == 0);
}

TEST_CASE("DeviceAddressMap: ranges at both ends of the 64-bit space", "[state][address_map]") {
  DeviceAddressMap map;
  const VkBuffer top = FakeBuffer(1);
  const VkBuffer bottom = FakeBuffer(2);
  REQUIRE(map.Insert(kTop - 0xf, 0x10, top));  // last byte is 2^64 - 1
  REQUIRE(map.Insert(0, 0x10, bottom));

  CHECK(Containing(map, kTop) == std::vector<VkBuffer>{top});
  CHECK(Containing(map, kTop - 0xf) == std::vector<VkBuffer>{top});
  CHECK(Containing(map, kTop - 0x10).empty());
  CHECK(Containing(map, 0) == std::vector<VkBuffer>{bottom});
  CHECK(Containing(map, 0x10).empty());
  CHECK(map.FindCovering(kTop - 0xf, 0x10).has_value());
  CHECK(map.FindCovering(kTop, 1).has_value());
  CHECK_FALSE(map.FindCovering(kTop, 2).has_value());  // the query itself wraps
  CHECK(map.RangeOf(top)->size == 0x10);

  // The largest range that fits: [1, 2^64).
  const VkBuffer huge = FakeBuffer(3);
  REQUIRE(map.Insert(1, kTop, huge));
  CHECK(map.RangeOf(huge)->size == kTop);
  CHECK(Containing(map, kTop) == std::vector<VkBuffer>{top, huge});
  CHECK(Containing(map, 0) == std::vector<VkBuffer>{bottom});

  CHECK(map.Erase(top));
  CHECK(map.Erase(huge));
  CHECK(map.Erase(bottom));
  CHECK(map.SegmentCount() == 0);
}

TEST_CASE("DeviceAddressMap: aliasing buffers on the same range", "[state][address_map]") {
  DeviceAddressMap map;
  const VkBuffer a = FakeBuffer(1);
  const VkBuffer b = FakeBuffer(2);
  REQUIRE(map.Insert(0x4000, 0x1000, b));
  REQUIRE(map.Insert(0x4000, 0x1000, a));
  CHECK(Containing(map, 0x4800) == std::vector<VkBuffer>{a, b});  // handle order

  CHECK(map.FindCovering(0x4000, 0x1000)->buffer == a);
  CHECK(map.FindCovering(0x4000, 0x1000, [b](VkBuffer x) { return x == b; })->buffer == b);
  CHECK_FALSE(map.FindCovering(0x4000, 0x1000, [](VkBuffer) { return false; }).has_value());

  CHECK(map.Erase(a));
  CHECK(Containing(map, 0x4800) == std::vector<VkBuffer>{b});
  CHECK(map.SegmentCount() == 2);
}

TEST_CASE("DeviceAddressMap: a whole-allocation buffer over sub-allocated buffers", "[state][address_map]") {
  DeviceAddressMap map;
  const VkBuffer whole = FakeBuffer(100);
  REQUIRE(map.Insert(0x10000, 0x10000, whole));
  for (std::uint64_t i = 0; i < 16; ++i) REQUIRE(map.Insert(0x10000 + i * 0x1000, 0x1000, FakeBuffer(i)));

  CHECK(Containing(map, 0x13800) == std::vector<VkBuffer>{FakeBuffer(3), whole});
  const auto not_whole = [whole](VkBuffer x) { return x != whole; };
  // Inside one slice: the slice qualifies; across two slices only the whole buffer does.
  CHECK(map.FindCovering(0x13800, 0x800, not_whole)->buffer == FakeBuffer(3));
  CHECK_FALSE(map.FindCovering(0x13800, 0x801, not_whole).has_value());
  CHECK(map.FindCovering(0x13800, 0x801)->buffer == whole);

  // The sub-allocator frees slices; the boundaries they created must go with them.
  for (std::uint64_t i = 0; i < 16; ++i) REQUIRE(map.Erase(FakeBuffer(i)));
  CHECK(map.SegmentCount() == 2);
  CHECK(Containing(map, 0x13800) == std::vector<VkBuffer>{whole});
}

TEST_CASE("DeviceAddressMap: partial overlaps", "[state][address_map]") {
  DeviceAddressMap map;
  const VkBuffer a = FakeBuffer(1);
  const VkBuffer b = FakeBuffer(2);
  REQUIRE(map.Insert(0x1000, 0x200, a));  // [0x1000, 0x1200)
  REQUIRE(map.Insert(0x1100, 0x200, b));  // [0x1100, 0x1300)
  CHECK(Containing(map, 0x10ff) == std::vector<VkBuffer>{a});
  CHECK(Containing(map, 0x1100) == std::vector<VkBuffer>{a, b});
  CHECK(Containing(map, 0x11ff) == std::vector<VkBuffer>{a, b});
  CHECK(Containing(map, 0x1200) == std::vector<VkBuffer>{b});
  CHECK_FALSE(map.FindCovering(0x1000, 0x300).has_value());  // the union covers it, no single buffer does
  CHECK(map.SegmentCount() == 4);
}

TEST_CASE("DeviceAddressMap: re-inserting a handle replaces its range", "[state][address_map]") {
  DeviceAddressMap map;
  const VkBuffer a = FakeBuffer(1);
  REQUIRE(map.Insert(0x1000, 0x100, a));
  REQUIRE(map.Insert(0x1000, 0x100, a));  // the same range twice: still one entry
  CHECK(Containing(map, 0x1000) == std::vector<VkBuffer>{a});
  CHECK(map.size() == 1);

  REQUIRE(map.Insert(0x8000, 0x100, a));  // recycled handle at a new address
  CHECK(Containing(map, 0x1000).empty());
  CHECK(Containing(map, 0x8000) == std::vector<VkBuffer>{a});
  CHECK(map.size() == 1);
  CHECK(map.SegmentCount() == 2);

  CHECK_FALSE(map.Insert(0x9000, 0, a));  // an invalid range still drops the stale one
  CHECK(map.empty());
}

TEST_CASE("DeviceAddressMap: address reuse after destroy", "[state][address_map]") {
  DeviceAddressMap map;
  REQUIRE(map.Insert(0x1000, 0x100, FakeBuffer(1)));
  REQUIRE(map.Erase(FakeBuffer(1)));
  REQUIRE(map.Insert(0x1000, 0x80, FakeBuffer(2)));
  CHECK(Containing(map, 0x1000) == std::vector<VkBuffer>{FakeBuffer(2)});
  CHECK(Containing(map, 0x1080).empty());
}

TEST_CASE("AddressHits: more than the inline capacity, then reuse", "[state][address_map]") {
  DeviceAddressMap map;
  for (std::uint64_t i = 0; i < 6; ++i) REQUIRE(map.Insert(0x1000, 0x100 + i, FakeBuffer(i)));
  AddressHits hits;
  CHECK(map.FindContaining(0x1000, hits) == 6);
  for (std::uint64_t i = 0; i < 6; ++i) {
    CHECK(hits[i].buffer == FakeBuffer(i));
    CHECK(hits[i].size == 0x100 + i);
  }
  CHECK(map.FindContaining(0x1102, hits) == 3);  // only the three longest reach it
  CHECK(Buffers(hits) == std::vector<VkBuffer>{FakeBuffer(3), FakeBuffer(4), FakeBuffer(5)});
  CHECK(map.FindContaining(0x2000, hits) == 0);
  CHECK(hits.begin() == hits.end());
}

TEST_CASE("DeviceAddressMap: readers during inserts and erases", "[state][address_map][threads]") {
  DeviceAddressMap map;
  const VkBuffer stable = FakeBuffer(0);
  REQUIRE(map.Insert(0x100000, 0x100000, stable));
  std::atomic<bool> done{false};
  std::atomic<int> errors{0};

  // The writer churns buffers inside and around the stable one, like a per-frame sub-allocator.
  std::thread writer([&] {
    for (std::uint64_t round = 0; round < 50; ++round) {
      for (std::uint64_t i = 1; i <= 8; ++i) {
        map.Insert(0x0f0000 + (round % 7 + i) * 0x8000, 0x9000, FakeBuffer(i));
      }
      for (std::uint64_t i = 1; i <= 8; i += 2) map.Erase(FakeBuffer(i));
    }
    done = true;
  });
  std::vector<std::thread> readers;
  for (int r = 0; r < 2; ++r) {
    readers.emplace_back([&, r] {
      AddressHits hits;
      std::uint64_t step = 0;
      while (!done || step < 2000) {  // a minimum of work even if the writer wins the race
        const VkDeviceAddress addr = 0x100000 + ((step++ * 0x1234 + static_cast<std::uint64_t>(r)) % 0x100000);
        map.FindContaining(addr, hits);
        bool saw_stable = false;
        for (const AddressHit& hit : hits) {
          saw_stable |= hit.buffer == stable;
          if (addr < hit.base || addr - hit.base >= hit.size) ++errors;
        }
        if (!saw_stable) ++errors;
        const auto covering = map.FindCovering(addr, 1, [stable](VkBuffer b) { return b == stable; });
        if (!covering || covering->buffer != stable) ++errors;
      }
    });
  }
  writer.join();
  for (auto& reader : readers) reader.join();
  CHECK(errors == 0);
  CHECK(map.size() == 5);  // the stable buffer and the four even ones
}

}  // namespace
}  // namespace asval
