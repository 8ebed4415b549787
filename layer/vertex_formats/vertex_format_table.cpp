// The vertex-format table, computed at compile time from vulkan_format_traits.hpp (Vulkan-Hpp's format
// traits, generated from the registry's vk.xml). Only this file parses vulkan.hpp; everything else includes
// the small asval/vertex_formats.h.
#include "asval/vertex_formats.h"

#include <vulkan/vulkan_format_traits.hpp>

#include <array>
#include <cstddef>
#include <iterator>

namespace asval {
namespace {

namespace traits = VULKAN_HPP_NAMESPACE;
using HppFormat = VULKAN_HPP_NAMESPACE::Format;

// The formats the builder decodes (DecodeVertex, the classifier's loops). The mandatory ones come from the
// specification's format tables (formats.adoc: VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR
// is required for these six); the optional ones are those Mesa's vertex loader handles plus the
// 3-component variants the headers name. Order is stable: tests and benchmarks iterate it.
constexpr VkFormat kDecodable[] = {
    VK_FORMAT_R32G32_SFLOAT,       VK_FORMAT_R32G32B32_SFLOAT,       VK_FORMAT_R32G32B32A32_SFLOAT,
    VK_FORMAT_R16G16_SFLOAT,       VK_FORMAT_R16G16B16_SFLOAT,       VK_FORMAT_R16G16B16A16_SFLOAT,
    VK_FORMAT_R16G16_SNORM,        VK_FORMAT_R16G16B16_SNORM,        VK_FORMAT_R16G16B16A16_SNORM,
    VK_FORMAT_R16G16_UNORM,        VK_FORMAT_R16G16B16_UNORM,        VK_FORMAT_R16G16B16A16_UNORM,
    VK_FORMAT_R8G8_SNORM,          VK_FORMAT_R8G8B8_SNORM,           VK_FORMAT_R8G8B8A8_SNORM,
    VK_FORMAT_R8G8_UNORM,          VK_FORMAT_R8G8B8_UNORM,           VK_FORMAT_R8G8B8A8_UNORM,
    VK_FORMAT_A2B10G10R10_UNORM_PACK32,
};
constexpr VkFormat kMandatory[] = {
    VK_FORMAT_R32G32_SFLOAT, VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R16G16_SFLOAT,
    VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16_SNORM, VK_FORMAT_R16G16B16A16_SNORM,
};
// Extension formats the table describes beyond the indexed core range (the 4444 formats of
// VK_EXT_4444_formats, NVIDIA's fixed-point R16G16_S10_5). Others (multi-planar and other YCbCr formats,
// PVRTC, ...) stay undescribed: the checks count them as unknown rather than guess.
constexpr VkFormat kOtherDescribed[] = {
    VK_FORMAT_A4R4G4B4_UNORM_PACK16,
    VK_FORMAT_A4B4G4R4_UNORM_PACK16,
    VK_FORMAT_R16G16_S10_5_NV,
};

constexpr bool Same(const char* a, const char* b) {
    while (*a != '\0' && *a == *b) {
        ++a;
        ++b;
    }
    return *a == *b;
}

template <std::size_t N>
constexpr bool Contains(const VkFormat (&list)[N], VkFormat format) {
    for (VkFormat f : list) {
        if (f == format) return true;
    }
    return false;
}

// A colour format with one texel per block in one plane: the only kind a vertex can have. The traits are
// asked only about components that exist (they assert on others).
constexpr bool IsPlainColour(HppFormat f) {
    if (traits::blockSize(f) == 0 || traits::isCompressed(f) || traits::planeCount(f) != 1 ||
        traits::texelsPerBlock(f) != 1) {
        return false;
    }
    for (uint8_t c = 0; c < traits::componentCount(f); ++c) {
        const char* name = traits::componentName(f, c);
        if (Same(name, "D") || Same(name, "S")) return false;
    }
    return true;
}

// The component that holds X: R where the format has one, else the first.
constexpr uint8_t XComponent(HppFormat f) {
    for (uint8_t c = 0; c < traits::componentCount(f); ++c) {
        if (Same(traits::componentName(f, c), "R")) return c;
    }
    return 0;
}

constexpr ComponentKind KindOf(HppFormat f, uint8_t x) {
    const char* numeric = traits::componentNumericFormat(f, x);
    if (traits::packed(f) != 0) return ComponentKind::Unorm1010102;  // the one packed decodable format (asserted below)
    if (Same(numeric, "SFLOAT")) return traits::componentBits(f, x) == 32 ? ComponentKind::Float32 : ComponentKind::Float16;
    if (Same(numeric, "SNORM")) return ComponentKind::Snorm;
    return ComponentKind::Unorm;
}

constexpr VertexFormatInfo FactsOf(VkFormat format) {
    VertexFormatInfo info;
    info.format = format;
    const auto f = static_cast<HppFormat>(format);
    if (format == VK_FORMAT_UNDEFINED || !IsPlainColour(f)) return info;
    info.vertexBytes = traits::blockSize(f);
    info.packed = traits::packed(f) != 0;
    uint8_t smallest = 0xFF;
    for (uint8_t c = 0; c < traits::componentCount(f); ++c) {
        const uint8_t bits = traits::componentBits(f, c);
        if (bits < smallest) smallest = bits;
    }
    info.componentBytes = info.packed ? static_cast<uint8_t>(traits::packed(f) / 8) : static_cast<uint8_t>(smallest / 8);
    const uint8_t x = XComponent(f);
    info.hasNaN = Same(traits::componentNumericFormat(f, x), "SFLOAT") || Same(traits::componentNumericFormat(f, x), "UFLOAT");
    if (Contains(kDecodable, format)) {
        info.decodable = true;
        info.mandatory = Contains(kMandatory, format);
        info.kind = KindOf(f, x);
        info.componentBits = traits::componentBits(f, x);
        info.componentCount = traits::componentCount(f);
    }
    return info;
}

constexpr std::array<VertexFormatInfo, vertex_format_table::kIndexedCount> MakeIndexed() {
    std::array<VertexFormatInfo, vertex_format_table::kIndexedCount> t{};
    for (uint32_t v = 0; v < vertex_format_table::kIndexedCount; ++v) t[v] = FactsOf(static_cast<VkFormat>(v));
    return t;
}

template <std::size_t N>
constexpr std::array<VertexFormatInfo, N> MakeList(const VkFormat (&formats)[N]) {
    std::array<VertexFormatInfo, N> t{};
    for (std::size_t i = 0; i < N; ++i) t[i] = FactsOf(formats[i]);
    return t;
}

constexpr std::array<VertexFormatInfo, std::size(kDecodable)> kDecodableRows = MakeList(kDecodable);
constexpr std::array<VertexFormatInfo, std::size(kOtherDescribed)> kOtherRows = MakeList(kOtherDescribed);
constexpr VertexFormatInfo kUndescribed{};

constexpr bool DecodableRowsAreIndexedAndDecoderReady() {
    for (const VertexFormatInfo& row : kDecodableRows) {
        // Every decodable format is in the indexed range, so the builder's lookups are table lookups too.
        if (static_cast<uint32_t>(row.format) >= vertex_format_table::kIndexedCount) return false;
        // DecodeVertex knows one packed layout only (X in bits 0..9).
        if (row.packed && row.format != VK_FORMAT_A2B10G10R10_UNORM_PACK32) return false;
        if (row.vertexBytes == 0 || row.componentBytes == 0) return false;
    }
    return true;
}
static_assert(DecodableRowsAreIndexedAndDecoderReady());

constexpr bool OtherRowsAreDescribed() {
    for (const VertexFormatInfo& row : kOtherRows) {
        if (row.vertexBytes == 0 || row.componentBytes == 0) return false;
    }
    return true;
}
static_assert(OtherRowsAreDescribed());

// The checks test multiples of componentBytes with a mask.
constexpr bool UnitsArePowersOfTwo() {
    for (const VertexFormatInfo& row : MakeIndexed()) {
        if ((row.componentBytes & (row.componentBytes - 1)) != 0) return false;
    }
    for (const VertexFormatInfo& row : kOtherRows) {
        if ((row.componentBytes & (row.componentBytes - 1)) != 0) return false;
    }
    return true;
}
static_assert(UnitsArePowersOfTwo());

}  // namespace

namespace vertex_format_table {

// Constant-initialised: no code runs at load time; external linkage from the declaration in the header.
constexpr std::array<VertexFormatInfo, kIndexedCount> kIndexed = MakeIndexed();

const VertexFormatInfo& OtherFormat(VkFormat format) {
    for (const VertexFormatInfo& row : kOtherRows) {
        if (row.format == format) return row;
    }
    return kUndescribed;
}

}  // namespace vertex_format_table

const VertexFormatInfo* DecodableVertexFormatsBegin() { return kDecodableRows.data(); }
const VertexFormatInfo* DecodableVertexFormatsEnd() { return kDecodableRows.data() + kDecodableRows.size(); }

}  // namespace asval
