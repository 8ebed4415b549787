// One table of vertex-format facts, read by the record-time checks (alignment, address ranges, size query)
// and by the reference builder (decode, NaN tests). It is its own tiny library, not part of layer/checks or
// layer/builder, because both need it and the builder must not depend on the loader or on the checks; it
// depends on the Vulkan headers only. The values come from vulkan_format_traits.hpp (libvulkan-dev), turned
// into a constant table when vertex_format_table.cpp is compiled (the only file that parses vulkan.hpp).
#pragma once

#include <vulkan/vulkan_core.h>

#include <array>
#include <cstdint>

namespace asval {

// How the builder decodes a component (the specification's conversion rules, see DecodeVertex).
enum class ComponentKind : uint8_t {
    Float32,     // IEEE binary32
    Float16,     // IEEE binary16
    Snorm,       // max(c / (2^(b-1) - 1), -1)
    Unorm,       // c / (2^b - 1)
    Unorm1010102 // A2B10G10R10_UNORM_PACK32: X = bits 0..9, Y = 10..19, Z = 20..29
};

struct VertexFormatInfo {
    VkFormat format = VK_FORMAT_UNDEFINED;
    // Facts of every colour format the table describes (0 / false for the formats it does not: depth,
    // compressed, multi-planar, extensions other than those in vertex_format_table.cpp, newer than the headers).
    uint8_t vertexBytes = 0;      // bytes of one texel: the bytes a build reads per vertex
    uint8_t componentBytes = 0;   // the alignment unit of pInfos-03711, vertexStride-03735 and primitiveOffset-03657:
                                  // the size of the format if packed, else its smallest component's size
    bool packed = false;          // a packed format (componentBytes is then the size of the whole texel)
    bool hasNaN = false;          // the first component (X, the R channel) is floating point and so can be NaN
                                  // (false: every triangle of this format is active)
    // The formats the builder decodes as acceleration-structure vertices (decodable); zero elsewhere.
    bool decodable = false;
    bool mandatory = false;       // VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR is required
    ComponentKind kind = ComponentKind::Float32;
    uint8_t componentBits = 0;    // bits of the X component: 32, 16, 8 or 10
    uint8_t componentCount = 0;   // 2, 3 or 4 (components beyond Z are ignored; 2-component formats have Z = 0)
};

namespace vertex_format_table {

// Core formats VK_FORMAT_UNDEFINED .. VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 (every core colour format, and every
// decodable one) are indexed by their value: the checks look a format up once per triangle geometry of every
// recorded build, so that lookup is one bounds test and one load.
inline constexpr uint32_t kIndexedCount = VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 + 1;
// Hidden: the layer is one shared object, so the checks reach the table PC-relative, not through the GOT.
extern const std::array<VertexFormatInfo, kIndexedCount> kIndexed __attribute__((visibility("hidden")));

// Every other value: a short search, out of line (rare formats; an all-zero row for those not described).
const VertexFormatInfo& OtherFormat(VkFormat format);

}  // namespace vertex_format_table

inline const VertexFormatInfo& VertexFormatFacts(VkFormat format) {
    const auto value = static_cast<uint32_t>(format);
    return value < vertex_format_table::kIndexedCount ? vertex_format_table::kIndexed[value]
                                                      : vertex_format_table::OtherFormat(format);
}

// The decodable formats, in a stable order (tests and benchmarks iterate them).
const VertexFormatInfo* DecodableVertexFormatsBegin();
const VertexFormatInfo* DecodableVertexFormatsEnd();

}  // namespace asval
