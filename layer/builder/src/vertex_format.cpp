#include "asval/builder/vertex_format.h"

#include <cstring>
#include <iterator>

#include "format_traits.h"

namespace asval::builder {
namespace {

// Mandatory set from formats.adoc; the optional ones are those Mesa's vertex loader handles plus the
// 3-component variants the headers name. Order is stable: tests and benchmarks iterate it.
constexpr VertexFormatInfo kFormats[] = {
    {VK_FORMAT_R32G32_SFLOAT, ComponentKind::Float32, 32, 2, 8, 4, true, true},
    {VK_FORMAT_R32G32B32_SFLOAT, ComponentKind::Float32, 32, 3, 12, 4, true, true},
    {VK_FORMAT_R32G32B32A32_SFLOAT, ComponentKind::Float32, 32, 4, 16, 4, true, false},
    {VK_FORMAT_R16G16_SFLOAT, ComponentKind::Float16, 16, 2, 4, 2, true, true},
    {VK_FORMAT_R16G16B16_SFLOAT, ComponentKind::Float16, 16, 3, 6, 2, true, false},
    {VK_FORMAT_R16G16B16A16_SFLOAT, ComponentKind::Float16, 16, 4, 8, 2, true, true},
    {VK_FORMAT_R16G16_SNORM, ComponentKind::Snorm, 16, 2, 4, 2, false, true},
    {VK_FORMAT_R16G16B16_SNORM, ComponentKind::Snorm, 16, 3, 6, 2, false, false},
    {VK_FORMAT_R16G16B16A16_SNORM, ComponentKind::Snorm, 16, 4, 8, 2, false, true},
    {VK_FORMAT_R16G16_UNORM, ComponentKind::Unorm, 16, 2, 4, 2, false, false},
    {VK_FORMAT_R16G16B16_UNORM, ComponentKind::Unorm, 16, 3, 6, 2, false, false},
    {VK_FORMAT_R16G16B16A16_UNORM, ComponentKind::Unorm, 16, 4, 8, 2, false, false},
    {VK_FORMAT_R8G8_SNORM, ComponentKind::Snorm, 8, 2, 2, 1, false, false},
    {VK_FORMAT_R8G8B8_SNORM, ComponentKind::Snorm, 8, 3, 3, 1, false, false},
    {VK_FORMAT_R8G8B8A8_SNORM, ComponentKind::Snorm, 8, 4, 4, 1, false, false},
    {VK_FORMAT_R8G8_UNORM, ComponentKind::Unorm, 8, 2, 2, 1, false, false},
    {VK_FORMAT_R8G8B8_UNORM, ComponentKind::Unorm, 8, 3, 3, 1, false, false},
    {VK_FORMAT_R8G8B8A8_UNORM, ComponentKind::Unorm, 8, 4, 4, 1, false, false},
    {VK_FORMAT_A2B10G10R10_UNORM_PACK32, ComponentKind::Unorm1010102, 10, 4, 4, 4, false, false},
};

}  // namespace

const VertexFormatInfo* FindVertexFormat(VkFormat format) {
    for (const VertexFormatInfo& f : kFormats) {
        if (f.format == format) return &f;
    }
    return nullptr;
}

const VertexFormatInfo* VertexFormatsBegin() { return std::begin(kFormats); }
const VertexFormatInfo* VertexFormatsEnd() { return std::end(kFormats); }

int IndexTypeBytes(VkIndexType type) {
    switch (type) {
        case VK_INDEX_TYPE_NONE_KHR: return 0;
        case VK_INDEX_TYPE_UINT16: return 2;
        case VK_INDEX_TYPE_UINT32: return 4;
#ifdef VK_EXT_index_type_uint8
        case VK_INDEX_TYPE_UINT8_EXT: return 1;
#endif
        default: return -1;
    }
}

void DecodeVertex(const VertexFormatInfo& info, const void* vertex, float xyz[3]) {
    const auto* p = static_cast<const uint8_t*>(vertex);
    switch (info.kind) {
        case ComponentKind::Float32:
            for (int c = 0; c < 3; ++c) xyz[c] = c < info.componentCount ? detail::LoadF32(p + 4 * c) : 0.0f;
            return;
        case ComponentKind::Float16:
            for (int c = 0; c < 3; ++c)
                xyz[c] = c < info.componentCount ? detail::HalfToFloat(detail::LoadU16(p + 2 * c)) : 0.0f;
            return;
        case ComponentKind::Snorm:
            for (int c = 0; c < 3; ++c) {
                if (c >= info.componentCount) { xyz[c] = 0.0f; continue; }
                const int32_t code = info.componentBits == 8 ? int32_t(int8_t(p[c]))
                                                             : int32_t(int16_t(detail::LoadU16(p + 2 * c)));
                xyz[c] = detail::SnormToFloat(code, info.componentBits);
            }
            return;
        case ComponentKind::Unorm:
            for (int c = 0; c < 3; ++c) {
                if (c >= info.componentCount) { xyz[c] = 0.0f; continue; }
                const uint32_t code = info.componentBits == 8 ? p[c] : detail::LoadU16(p + 2 * c);
                xyz[c] = detail::UnormToFloat(code, info.componentBits);
            }
            return;
        case ComponentKind::Unorm1010102: {
            const uint32_t w = detail::LoadU32(p);
            for (int c = 0; c < 3; ++c) xyz[c] = detail::UnormToFloat((w >> (10 * c)) & 0x3FFu, 10);
            return;
        }
    }
}

}  // namespace asval::builder
