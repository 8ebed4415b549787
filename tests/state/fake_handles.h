// Test helpers: made-up Vulkan handles and a seeded random source whose sequence is the same everywhere.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

namespace asval::test {

// Non-dispatchable handles are pointers on 64-bit and uint64_t on 32-bit builds; real ones are usually
// 16-byte aligned, which the fakes imitate.
template <typename Handle>
Handle FakeHandle(std::uint64_t id) {
  const std::uint64_t bits = 0x10000 + id * 16;
#if defined(VK_USE_64_BIT_PTR_DEFINES) && VK_USE_64_BIT_PTR_DEFINES == 1
  return reinterpret_cast<Handle>(static_cast<std::uintptr_t>(bits));
#else
  return static_cast<Handle>(bits);
#endif
}
// The id a FakeHandle was made from.
template <typename Handle>
std::uint64_t FakeId(Handle handle) {
#if defined(VK_USE_64_BIT_PTR_DEFINES) && VK_USE_64_BIT_PTR_DEFINES == 1
  const auto bits = static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(handle));
#else
  const auto bits = static_cast<std::uint64_t>(handle);
#endif
  return (bits - 0x10000) / 16;
}
inline VkBuffer FakeBuffer(std::uint64_t id) { return FakeHandle<VkBuffer>(id); }
inline VkDeviceMemory FakeMemory(std::uint64_t id) { return FakeHandle<VkDeviceMemory>(id); }

// SplitMix64: tiny and fully specified, unlike std::uniform_int_distribution whose output differs between
// standard libraries. Tests stay reproducible from the seed alone.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t Next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform enough in [0, bound) for test data (bound > 0).
  std::uint64_t Below(std::uint64_t bound) { return Next() % bound; }

 private:
  std::uint64_t state_;
};

}  // namespace asval::test
