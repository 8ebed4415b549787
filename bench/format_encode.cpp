#include "format_encode.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "asval/builder/vertex_format.h"

namespace bench {
namespace {

uint16_t FloatToHalf(float f) {  // round to nearest even; inputs here are finite and small
    uint32_t b;
    std::memcpy(&b, &f, 4);
    const uint32_t sign = (b >> 16) & 0x8000u;
    const int exp = int((b >> 23) & 0xFF) - 127 + 15;
    uint32_t mant = b & 0x7FFFFFu;
    if (exp >= 31) return uint16_t(sign | 0x7C00u);
    if (exp <= 0) {
        if (exp < -10) return uint16_t(sign);
        mant |= 0x800000u;
        const int shift = 14 - exp;
        uint32_t h = mant >> shift;
        const uint32_t rem = mant & ((1u << shift) - 1), halfway = 1u << (shift - 1);
        if (rem > halfway || (rem == halfway && (h & 1))) ++h;
        return uint16_t(sign | h);
    }
    uint32_t h = (uint32_t(exp) << 10) | (mant >> 13);
    const uint32_t rem = mant & 0x1FFFu;
    if (rem > 0x1000u || (rem == 0x1000u && (h & 1))) ++h;
    return uint16_t(sign | h);
}

}  // namespace

EncodedScene Encode(const scenes::Scene& s, VkFormat format) {
    using namespace asval::builder;
    const VertexFormatInfo& f = *FindVertexFormat(format);
    EncodedScene e;
    const size_t count = s.vertices.size() / 3;
    e.vertices.assign(count * f.vertexBytes, 0);
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < count; ++i)
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], s.vertices[3 * i + size_t(a)]);
            hi[a] = std::max(hi[a], s.vertices[3 * i + size_t(a)]);
        }
    for (size_t i = 0; i < count; ++i) {
        uint8_t* p = e.vertices.data() + i * f.vertexBytes;
        for (int a = 0; a < 3; ++a) {
            const float v = s.vertices[3 * i + size_t(a)];
            const float unit = hi[a] > lo[a] ? (v - lo[a]) / (hi[a] - lo[a]) : 0.5f;  // [0, 1]
            switch (f.kind) {
                case ComponentKind::Float32:
                    if (a < f.componentCount) std::memcpy(p + 4 * a, &v, 4);
                    break;
                case ComponentKind::Float16:
                    if (a < f.componentCount) { const uint16_t h = FloatToHalf(v); std::memcpy(p + 2 * a, &h, 2); }
                    break;
                case ComponentKind::Snorm: {
                    if (a >= f.componentCount) break;
                    const int maxCode = (1 << (f.componentBits - 1)) - 1;
                    const int code = int(std::lround((unit * 2 - 1) * maxCode));
                    if (f.componentBits == 8) p[a] = uint8_t(int8_t(code));
                    else { const int16_t c = int16_t(code); std::memcpy(p + 2 * a, &c, 2); }
                    break;
                }
                case ComponentKind::Unorm: {
                    if (a >= f.componentCount) break;
                    const uint32_t code = uint32_t(std::lround(unit * double((1u << f.componentBits) - 1)));
                    if (f.componentBits == 8) p[a] = uint8_t(code);
                    else { const uint16_t c = uint16_t(code); std::memcpy(p + 2 * a, &c, 2); }
                    break;
                }
                case ComponentKind::Unorm1010102: {
                    uint32_t w;
                    std::memcpy(&w, p, 4);
                    w |= uint32_t(std::lround(unit * 1023.0)) << (10 * a);
                    std::memcpy(p, &w, 4);
                    break;
                }
            }
        }
    }
    e.view = scenes::View(s);
    e.view.vertexData = e.vertices.data();
    e.view.vertexDataBytes = e.vertices.size();
    e.view.vertexFormat = format;
    e.view.vertexStride = f.vertexBytes;
    return e;
}

}  // namespace bench
