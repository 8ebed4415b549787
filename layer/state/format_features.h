#pragma once
// The device's buffer format features, asked of the driver once per format and cached: the build commands'
// vertexFormat-03797 reads them for every triangle geometry, so a steady-state frame must not call the
// driver. Lookups of core formats are one relaxed atomic load; formats from extensions go through a small
// sharded map.
#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <new>
#include <optional>
#include <string_view>

#include "concurrent_map.h"
#include "vk_enum_string.h"

namespace asval {

class FormatFeatureCache {
 public:
  // Set while vkCreateDevice runs (before any other thread sees the device): the physical device and the
  // next layer's vkGetPhysicalDeviceFormatProperties (the instance dispatch, never the app's pointer).
  void Init(VkPhysicalDevice gpu, PFN_vkGetPhysicalDeviceFormatProperties query) {
    gpu_ = gpu;
    query_ = query;
  }

  // VkFormatProperties::bufferFeatures of `format`. nullopt when the layer cannot ask: no query function, or
  // a format these headers do not name (an extension newer than the layer: the driver may know it, but the
  // question would be invalid usage for the layer's own headers, and guessing is worse than skipping).
  std::optional<VkFormatFeatureFlags> BufferFeatures(VkFormat format) const {
    const auto value = static_cast<uint32_t>(format);
    if (value < kCoreFormatCount) {
      const uint64_t slot = core_[value].load(std::memory_order_relaxed);
      if (slot != 0) return static_cast<VkFormatFeatureFlags>(slot & 0xffffffffu);
    }
    return FirstLookup(format);
  }

 private:
  // VK_FORMAT_UNDEFINED .. VK_FORMAT_ASTC_12x12_SRGB_BLOCK: the contiguous core 1.0 range.
  static constexpr uint32_t kCoreFormatCount = VK_FORMAT_ASTC_12x12_SRGB_BLOCK + 1;
  static constexpr uint64_t kQueried = uint64_t{1} << 32;

  // Everything but a cached core format: the first question about a format, and extension formats.
  [[gnu::noinline]] std::optional<VkFormatFeatureFlags> FirstLookup(VkFormat format) const {
    if (!query_) return std::nullopt;
    const auto value = static_cast<uint32_t>(format);
    if (value < kCoreFormatCount) {
      // Two threads may both ask the first time; they store the same answer.
      const uint64_t slot = kQueried | Query(format);
      core_[value].store(slot, std::memory_order_relaxed);
      return static_cast<VkFormatFeatureFlags>(slot & 0xffffffffu);
    }
    if (std::optional<VkFormatFeatureFlags> cached = extension_formats_.find(format)) return cached;
    if (!KnownToHeaders(format)) return std::nullopt;
    const VkFormatFeatureFlags features = Query(format);
    try {
      extension_formats_.insert_or_assign(format, features);
    } catch (const std::bad_alloc&) {
      // Not cached: asked again next time.
    }
    return features;
  }

  static bool KnownToHeaders(VkFormat format) {
    return std::string_view(string_VkFormat(format)).rfind("VK_FORMAT_", 0) == 0;
  }

  VkFormatFeatureFlags Query(VkFormat format) const {
    VkFormatProperties properties{};
    query_(gpu_, format, &properties);
    return properties.bufferFeatures;
  }

  VkPhysicalDevice gpu_ = VK_NULL_HANDLE;
  PFN_vkGetPhysicalDeviceFormatProperties query_ = nullptr;
  mutable std::array<std::atomic<uint64_t>, kCoreFormatCount> core_{};  // 0: not asked yet
  mutable ConcurrentMap<VkFormat, VkFormatFeatureFlags, 2> extension_formats_;
};

}  // namespace asval
