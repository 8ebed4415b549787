#include "asval/builder/vertex_format.h"

#include <cstring>

#include "format_traits.h"

namespace asval::builder {

const VertexFormatInfo* FindVertexFormat(VkFormat format) {
    const VertexFormatInfo& facts = VertexFormatFacts(format);
    return facts.decodable ? &facts : nullptr;
}

const VertexFormatInfo* VertexFormatsBegin() { return DecodableVertexFormatsBegin(); }
const VertexFormatInfo* VertexFormatsEnd() { return DecodableVertexFormatsEnd(); }

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
