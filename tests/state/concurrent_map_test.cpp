#include "state/concurrent_map.h"

#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "fake_handles.h"

namespace asval {
namespace {

using test::FakeBuffer;

TEST_CASE("ConcurrentMap: single-thread operations", "[state][concurrent_map]") {
  ConcurrentMap<VkBuffer, int> map;
  const VkBuffer a = FakeBuffer(1);
  const VkBuffer b = FakeBuffer(2);

  CHECK(map.empty());
  CHECK_FALSE(map.find(a).has_value());
  CHECK(map.insert_or_assign(a, 1));
  CHECK_FALSE(map.insert_or_assign(a, 2));  // overwrite: not new
  CHECK(map.find(a) == 2);
  CHECK_FALSE(map.emplace(a, 3));  // present: keeps the old value
  CHECK(map.find(a) == 2);
  CHECK(map.emplace(b, 4));
  CHECK(map.contains(b));
  CHECK(map.size() == 2);

  auto all = map.snapshot();
  std::sort(all.begin(), all.end(), [](const auto& x, const auto& y) { return x.second < y.second; });
  REQUIRE(all.size() == 2);
  CHECK(all[0] == std::pair<VkBuffer, int>(a, 2));
  CHECK(all[1] == std::pair<VkBuffer, int>(b, 4));
  CHECK(map.snapshot([](VkBuffer, int v) { return v > 3; }).size() == 1);

  CHECK(map.pop(a) == 2);
  CHECK_FALSE(map.pop(a).has_value());
  CHECK_FALSE(map.contains(a));
  CHECK(map.erase(b));
  CHECK_FALSE(map.erase(b));
  CHECK(map.empty());

  map.insert_or_assign(a, 5);
  map.clear();
  CHECK(map.size() == 0);
}

TEST_CASE("ConcurrentMap: values found before an erase stay alive", "[state][concurrent_map]") {
  ConcurrentMap<std::uint64_t, std::shared_ptr<std::string>> map;
  map.emplace(7, std::make_shared<std::string>("state"));
  const auto held = map.find(7);
  REQUIRE(held.has_value());
  const auto popped = map.pop(7);
  REQUIRE(popped.has_value());
  CHECK(popped->get() == held->get());
  CHECK(**held == "state");
  CHECK(held->use_count() == 2);  // `held` and `popped`; the map let go
}

TEST_CASE("ConcurrentMap: single shard and non-handle keys work", "[state][concurrent_map]") {
  ConcurrentMap<std::string, int, 0> map;
  for (int i = 0; i < 100; ++i) CHECK(map.emplace(std::to_string(i), i));
  CHECK(map.size() == 100);
  CHECK(map.find("42") == 42);
}

TEST_CASE("HandleHash spreads 16-byte aligned handles over the shard bits", "[state][concurrent_map]") {
  // The shard index is the top 4 bits of the hash. Without mixing, aligned small pointers would all land
  // in shard 0.
  constexpr int kKeys = 4096;
  std::array<int, 16> per_shard{};
  HandleHash<VkBuffer> hash;
  for (int i = 0; i < kKeys; ++i) ++per_shard[hash(FakeBuffer(static_cast<std::uint64_t>(i))) >> 60];
  for (int count : per_shard) {
    CHECK(count > kKeys / 16 / 2);
    CHECK(count < kKeys / 16 * 2);
  }
  // Low bits matter to the unordered_map inside a shard: they must not be constant either.
  std::array<int, 16> low{};
  for (int i = 0; i < kKeys; ++i) ++low[hash(FakeBuffer(static_cast<std::uint64_t>(i))) & 15];
  CHECK(*std::min_element(low.begin(), low.end()) > kKeys / 16 / 2);
}

TEST_CASE("ConcurrentMap: threads inserting, finding and erasing", "[state][concurrent_map][threads]") {
  constexpr int kThreads = 4;
  constexpr std::uint64_t kOwnKeys = 500;
  constexpr std::uint64_t kSharedKeys = 300;
  ConcurrentMap<VkBuffer, std::shared_ptr<const std::uint64_t>> map;
  std::atomic<int> emplace_wins{0};
  std::atomic<int> pop_wins{0};
  std::atomic<int> mismatches{0};

  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      const std::uint64_t first = 1000 + static_cast<std::uint64_t>(t) * kOwnKeys;
      // Keys only this thread writes: each must read back exactly what was written.
      for (std::uint64_t k = first; k < first + kOwnKeys; ++k) {
        map.insert_or_assign(FakeBuffer(k), std::make_shared<const std::uint64_t>(k));
      }
      for (std::uint64_t k = first; k < first + kOwnKeys; ++k) {
        const auto value = map.find(FakeBuffer(k));
        if (!value || **value != k) ++mismatches;
        if (k % 2 == 0 && !map.erase(FakeBuffer(k))) ++mismatches;
      }
      // Keys every thread races for: one emplace and one pop may win per key.
      for (std::uint64_t k = 0; k < kSharedKeys; ++k) {
        if (map.emplace(FakeBuffer(k), std::make_shared<const std::uint64_t>(k))) ++emplace_wins;
      }
      for (std::uint64_t k = 0; k < kSharedKeys; ++k) {
        if (const auto value = map.pop(FakeBuffer(k))) {
          ++pop_wins;
          if (**value != k) ++mismatches;
        }
      }
    });
  }
  for (auto& thread : threads) thread.join();

  CHECK(mismatches == 0);
  CHECK(emplace_wins >= static_cast<int>(kSharedKeys));  // a key popped early can be emplaced again
  CHECK(pop_wins == emplace_wins);                        // every value emplaced was popped exactly once
  CHECK(map.size() == kThreads * kOwnKeys / 2);           // the odd own keys remain
  for (const auto& [key, value] : map.snapshot()) CHECK(*value % 2 == 1);
}

}  // namespace
}  // namespace asval
