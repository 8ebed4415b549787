#pragma once
// The alignment a vertex format imposes on acceleration-structure build inputs: the size of the format if it
// is a packed format, else its component size (the smallest component, in bytes). Read by the rules on
// vertexData (pInfos-03711), vertexStride (03735) and primitiveOffset of non-indexed triangles (03657), once
// per triangle geometry each: a table lookup for the core formats.
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>

namespace asval {

struct VertexFormatAlignment {
  // A power of two (1, 2, 4 or 8), so the rules test multiples with a mask; 0: a format this table does not
  // describe (depth, compressed, multi-planar, newer than the headers).
  uint32_t bytes = 0;
  bool packed = false;  // true: bytes is the packed size of the whole texel

  // What `bytes` is, for messages: "... is not a multiple of 4 bytes, the component size of ...".
  const char* What() const { return packed ? "size of the packed format" : "component size"; }
};

namespace vertex_format_detail {

constexpr uint8_t kPacked = 0x80;
// Core 1.0 colour formats, VK_FORMAT_UNDEFINED .. VK_FORMAT_E5B9G9R9_UFLOAT_PACK32. They are laid out in runs
// of one component size (vulkan_core.h), so the table is written as those runs; tests/unit cross-checks it
// against the reference builder's vertex formats.
constexpr uint32_t kCoreCount = VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 + 1;

constexpr std::array<uint8_t, kCoreCount> MakeCoreTable() {
  std::array<uint8_t, kCoreCount> t{};
  const auto run = [&t](int first, int last, uint8_t value) {
    for (int f = first; f <= last; ++f) t[static_cast<size_t>(f)] = value;
  };
  run(VK_FORMAT_R4G4_UNORM_PACK8, VK_FORMAT_R4G4_UNORM_PACK8, 1 | kPacked);
  run(VK_FORMAT_R4G4B4A4_UNORM_PACK16, VK_FORMAT_A1R5G5B5_UNORM_PACK16, 2 | kPacked);
  run(VK_FORMAT_R8_UNORM, VK_FORMAT_B8G8R8A8_SRGB, 1);
  run(VK_FORMAT_A8B8G8R8_UNORM_PACK32, VK_FORMAT_A2B10G10R10_SINT_PACK32, 4 | kPacked);
  run(VK_FORMAT_R16_UNORM, VK_FORMAT_R16G16B16A16_SFLOAT, 2);
  run(VK_FORMAT_R32_UINT, VK_FORMAT_R32G32B32A32_SFLOAT, 4);
  run(VK_FORMAT_R64_UINT, VK_FORMAT_R64G64B64A64_SFLOAT, 8);
  run(VK_FORMAT_B10G11R11_UFLOAT_PACK32, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, 4 | kPacked);
  return t;
}

inline constexpr std::array<uint8_t, kCoreCount> kCoreTable = MakeCoreTable();

// Formats of extensions (A4R4G4B4, R16G16_S10_5_NV); out of line, rare.
VertexFormatAlignment ExtensionFormatAlignment(VkFormat format);

}  // namespace vertex_format_detail

inline VertexFormatAlignment AlignmentOfVertexFormat(VkFormat format) {
  const auto value = static_cast<uint32_t>(format);
  if (value >= vertex_format_detail::kCoreCount) return vertex_format_detail::ExtensionFormatAlignment(format);
  const uint8_t entry = vertex_format_detail::kCoreTable[value];
  return {static_cast<uint32_t>(entry & ~vertex_format_detail::kPacked), (entry & vertex_format_detail::kPacked) != 0};
}

// Bytes of one index of `type`: 2, 4, 1 (UINT8), 0 for VK_INDEX_TYPE_NONE_KHR, -1 for a value the headers
// do not name.
inline int IndexTypeSize(VkIndexType type) {
  switch (type) {
    case VK_INDEX_TYPE_NONE_KHR:
      return 0;
    case VK_INDEX_TYPE_UINT16:
      return 2;
    case VK_INDEX_TYPE_UINT32:
      return 4;
    case VK_INDEX_TYPE_UINT8_EXT:
      return 1;
    default:
      return -1;
  }
}

}  // namespace asval
