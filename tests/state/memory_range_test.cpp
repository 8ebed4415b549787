#include "state/memory_range.h"

#include <catch2/catch_test_macros.hpp>

#include <optional>
#include <vector>

#include "fake_handles.h"

namespace asval {
namespace {

using test::FakeMemory;
using test::Random;
constexpr VkDeviceSize kMax = ~VkDeviceSize{0};

TEST_CASE("ResolveMemorySpan maps buffer bytes onto the bound memory", "[state][memory_range]") {
  const MemoryBinding binding{FakeMemory(1), 0x400, true};
  const auto span = ResolveMemorySpan(binding, 0x80, 0x100);
  REQUIRE(span.has_value());
  CHECK(span->memory == FakeMemory(1));
  CHECK(span->begin == 0x480);
  CHECK(span->end == 0x580);

  CHECK_FALSE(ResolveMemorySpan(MemoryBinding{FakeMemory(1), 0, false}, 0, 16).has_value());  // not bound
  CHECK_FALSE(ResolveMemorySpan(MemoryBinding{VK_NULL_HANDLE, 0, true}, 0, 16).has_value());
  CHECK_FALSE(ResolveMemorySpan(MemoryBinding{FakeMemory(1), kMax - 4, true}, 5, 0).has_value());  // offset wraps
  CHECK_FALSE(ResolveMemorySpan(MemoryBinding{FakeMemory(1), kMax - 8, true}, 4, 5).has_value());  // end wraps
  CHECK(ResolveMemorySpan(MemoryBinding{FakeMemory(1), kMax - 8, true}, 4, 4)->end == kMax);
  const auto empty = ResolveMemorySpan(binding, 0x10, 0);
  REQUIRE(empty.has_value());
  CHECK(empty->begin == empty->end);
}

TEST_CASE("Overlaps: same memory, intersecting half-open ranges", "[state][memory_range]") {
  const MemorySpan a{FakeMemory(1), 0, 16};
  CHECK(Overlaps(a, MemorySpan{FakeMemory(1), 15, 32}));
  CHECK(Overlaps(MemorySpan{FakeMemory(1), 15, 32}, a));
  CHECK(Overlaps(a, MemorySpan{FakeMemory(1), 4, 8}));             // contained
  CHECK(Overlaps(a, a));
  CHECK_FALSE(Overlaps(a, MemorySpan{FakeMemory(1), 16, 32}));     // touching
  CHECK_FALSE(Overlaps(MemorySpan{FakeMemory(1), 16, 32}, a));
  CHECK_FALSE(Overlaps(a, MemorySpan{FakeMemory(2), 0, 16}));      // other memory
  CHECK_FALSE(Overlaps(a, MemorySpan{FakeMemory(1), 8, 8}));       // empty, even inside
  CHECK_FALSE(Overlaps(MemorySpan{VK_NULL_HANDLE, 0, 16}, MemorySpan{VK_NULL_HANDLE, 0, 16}));
}

TEST_CASE("FindOverlappingPair: scratch slices of one buffer", "[state][memory_range]") {
  // The batched-build pattern: 2000 infos, each with a 128-byte aligned slice of one scratch allocation,
  // using at most 128 bytes. Touching slices are fine.
  std::vector<MemorySpan> slices;
  for (VkDeviceSize i = 0; i < 2000; ++i) {
    const VkDeviceSize begin = 0x1000 + i * 128;
    slices.push_back({FakeMemory(7), begin, begin + 100 + i % 29});
  }
  CHECK_FALSE(FindOverlappingPair(slices).has_value());

  slices[1234].end += 64;  // one build uses more scratch than its slice
  const auto pair = FindOverlappingPair(slices);
  REQUIRE(pair.has_value());
  CHECK(pair->first == 1234);
  CHECK(pair->second == 1235);

  std::vector<MemorySpan> none;
  CHECK_FALSE(FindOverlappingPair(none).has_value());
}

TEST_CASE("FindOverlappingPair agrees with brute force", "[state][memory_range][model]") {
  Random random(0x0be1a9);
  std::vector<std::size_t> order;  // reused across calls like the layer will
  for (int trial = 0; trial < 3000; ++trial) {
    const std::size_t count = random.Below(24);
    std::vector<MemorySpan> spans;
    for (std::size_t i = 0; i < count; ++i) {
      const VkDeviceSize begin = random.Below(1024);
      const VkDeviceSize size = random.Below(6) == 0 ? 0 : random.Below(96);
      const VkDeviceMemory memory = random.Below(10) == 0 ? VK_NULL_HANDLE : FakeMemory(random.Below(3));
      spans.push_back({memory, begin, begin + size});
    }
    bool brute_force = false;
    for (std::size_t i = 0; i < count && !brute_force; ++i) {
      for (std::size_t j = i + 1; j < count && !brute_force; ++j) brute_force = Overlaps(spans[i], spans[j]);
    }
    const auto pair = FindOverlappingPair(spans.data(), spans.size(), order);
    REQUIRE(pair.has_value() == brute_force);
    if (pair) {
      REQUIRE(pair->first < pair->second);
      REQUIRE(pair->second < count);
      REQUIRE(Overlaps(spans[pair->first], spans[pair->second]));
    }
  }
}

}  // namespace
}  // namespace asval
