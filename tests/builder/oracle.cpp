#include "oracle.h"

#include <cmath>
#include <cstring>

namespace oracle {
namespace {

enum class Kind { Float, Snorm, Unorm, Packed1010102 };

struct Layout {
    Kind kind;
    unsigned bits;   // per component
    unsigned count;  // components stored
};

bool LayoutOf(VkFormat f, Layout* l) {
    switch (f) {
        case VK_FORMAT_R32G32_SFLOAT: *l = {Kind::Float, 32, 2}; return true;
        case VK_FORMAT_R32G32B32_SFLOAT: *l = {Kind::Float, 32, 3}; return true;
        case VK_FORMAT_R32G32B32A32_SFLOAT: *l = {Kind::Float, 32, 4}; return true;
        case VK_FORMAT_R16G16_SFLOAT: *l = {Kind::Float, 16, 2}; return true;
        case VK_FORMAT_R16G16B16_SFLOAT: *l = {Kind::Float, 16, 3}; return true;
        case VK_FORMAT_R16G16B16A16_SFLOAT: *l = {Kind::Float, 16, 4}; return true;
        case VK_FORMAT_R16G16_SNORM: *l = {Kind::Snorm, 16, 2}; return true;
        case VK_FORMAT_R16G16B16_SNORM: *l = {Kind::Snorm, 16, 3}; return true;
        case VK_FORMAT_R16G16B16A16_SNORM: *l = {Kind::Snorm, 16, 4}; return true;
        case VK_FORMAT_R16G16_UNORM: *l = {Kind::Unorm, 16, 2}; return true;
        case VK_FORMAT_R16G16B16_UNORM: *l = {Kind::Unorm, 16, 3}; return true;
        case VK_FORMAT_R16G16B16A16_UNORM: *l = {Kind::Unorm, 16, 4}; return true;
        case VK_FORMAT_R8G8_SNORM: *l = {Kind::Snorm, 8, 2}; return true;
        case VK_FORMAT_R8G8B8_SNORM: *l = {Kind::Snorm, 8, 3}; return true;
        case VK_FORMAT_R8G8B8A8_SNORM: *l = {Kind::Snorm, 8, 4}; return true;
        case VK_FORMAT_R8G8_UNORM: *l = {Kind::Unorm, 8, 2}; return true;
        case VK_FORMAT_R8G8B8_UNORM: *l = {Kind::Unorm, 8, 3}; return true;
        case VK_FORMAT_R8G8B8A8_UNORM: *l = {Kind::Unorm, 8, 4}; return true;
        case VK_FORMAT_A2B10G10R10_UNORM_PACK32: *l = {Kind::Packed1010102, 10, 4}; return true;
        default: return false;
    }
}

// Little-endian unsigned field of `bytes` bytes.
uint64_t ReadLE(const uint8_t* p, unsigned bytes) {
    uint64_t v = 0;
    for (unsigned i = 0; i < bytes; ++i) v |= uint64_t(p[i]) << (8 * i);
    return v;
}

// IEEE 754 binary interchange format with `expBits` exponent and `mantBits` fraction bits.
Component DecodeIeee(uint64_t bits, unsigned expBits, unsigned mantBits) {
    const uint64_t mant = bits & ((uint64_t(1) << mantBits) - 1);
    const uint64_t exp = (bits >> mantBits) & ((uint64_t(1) << expBits) - 1);
    const bool negative = (bits >> (mantBits + expBits)) & 1;
    const uint64_t expMax = (uint64_t(1) << expBits) - 1;
    const long bias = (long(1) << (expBits - 1)) - 1;
    Component c;
    if (exp == expMax) {
        if (mant != 0) { c.nan = true; return c; }  // every NaN: quiet, signalling, any sign or payload
        c.value = negative ? -HUGE_VALL : HUGE_VALL;
        return c;
    }
    long double m = (long double)mant;
    long double v = exp == 0 ? std::ldexp(m, int(1 - bias - long(mantBits)))
                             : std::ldexp(m + std::ldexp(1.0L, int(mantBits)), int(long(exp) - bias - long(mantBits)));
    c.value = negative ? -v : v;
    return c;
}

}  // namespace

bool FormatHasNaN(VkFormat format) {
    Layout l{};
    return LayoutOf(format, &l) && l.kind == Kind::Float;
}

unsigned VertexBytes(VkFormat format) {
    Layout l{};
    if (!LayoutOf(format, &l)) return 0;
    if (l.kind == Kind::Packed1010102) return 4;
    return l.bits / 8 * l.count;
}

bool DecodeVertex(VkFormat format, const uint8_t* p, Vertex* out) {
    Layout l{};
    if (!LayoutOf(format, &l)) return false;
    *out = Vertex{};
    for (unsigned i = 0; i < 3; ++i) {
        if (l.kind == Kind::Packed1010102) {
            // "R" is the least significant 10 bits; then G, then B.
            const uint64_t word = ReadLE(p, 4);
            out->c[i].value = (long double)((word >> (10 * i)) & 1023) / 1023.0L;
            continue;
        }
        if (i >= l.count) continue;  // missing Z reads as 0
        const uint64_t raw = ReadLE(p + i * (l.bits / 8), l.bits / 8);
        switch (l.kind) {
            case Kind::Float:
                out->c[i] = l.bits == 32 ? DecodeIeee(raw, 8, 23) : DecodeIeee(raw, 5, 10);
                break;
            case Kind::Snorm: {
                const long double half = std::ldexp(1.0L, int(l.bits) - 1);  // 2^(b-1)
                long double code = (long double)raw;
                if (code >= half) code -= 2 * half;  // two's complement
                long double v = code / (half - 1);
                out->c[i].value = v < -1 ? -1 : v;
                break;
            }
            case Kind::Unorm:
                out->c[i].value = (long double)raw / (std::ldexp(1.0L, int(l.bits)) - 1);
                break;
            case Kind::Packed1010102: break;
        }
    }
    return true;
}

Triangle ClassifyTriangle(const TriangleInput& in, uint32_t t) {
    Triangle r;
    uint64_t index[3];
    Vertex v[3];
    const unsigned indexBytes = in.indexType == VK_INDEX_TYPE_UINT16 ? 2
                              : in.indexType == VK_INDEX_TYPE_UINT32 ? 4
                              : in.indexType == VK_INDEX_TYPE_NONE_KHR ? 0 : 1;
    for (unsigned k = 0; k < 3; ++k) {
        const uint8_t* vp;
        uint64_t vertexNumber;
        if (indexBytes != 0) {
            // "primitiveCount x 3 indices are consumed from indexData, starting at primitiveOffset.
            //  The value of firstVertex is added to the index values before fetching vertices."
            index[k] = ReadLE(in.indexData + in.primitiveOffset + (3ull * t + k) * indexBytes, indexBytes);
            vertexNumber = index[k] + in.firstVertex;
            vp = in.vertexData + vertexNumber * in.stride;
        } else {
            // "consumed from vertexData, starting at an offset of primitiveOffset + vertexStride x firstVertex"
            vertexNumber = uint64_t(in.firstVertex) + 3ull * t + k;
            vp = in.vertexData + in.primitiveOffset + (vertexNumber - in.firstVertex) * in.stride +
                 uint64_t(in.firstVertex) * in.stride;
        }
        r.overMaxVertex |= vertexNumber > in.maxVertex;
        DecodeVertex(in.format, vp, &v[k]);
    }
    // "An inactive triangle is one for which the first (X) component of any vertex is NaN."
    if (v[0].c[0].nan || v[1].c[0].nan || v[2].c[0].nan) {
        r.active = false;
        return r;
    }
    for (auto& vert : v) r.undefined |= vert.c[1].nan || vert.c[2].nan;
    auto same = [](const Component& a, const Component& b) { return !a.nan && !b.nan && a.value == b.value; };
    auto identical = [&](const Vertex& a, const Vertex& b) {
        return same(a.c[0], b.c[0]) && same(a.c[1], b.c[1]) && same(a.c[2], b.c[2]);
    };
    // "one or more vertices whose respective (X), (Y), (Z) components are identical"
    bool degenerate = identical(v[0], v[1]) || identical(v[1], v[2]) || identical(v[0], v[2]);
    // "three vertices that have at least two of the (X), (Y), or (Z) components identical"
    int sharedAxes = 0;
    for (int a = 0; a < 3; ++a) sharedAxes += same(v[0].c[a], v[1].c[a]) && same(v[1].c[a], v[2].c[a]);
    degenerate |= sharedAxes >= 2;
    r.degenerate = degenerate;
    if (indexBytes != 0) r.sameIndex = index[0] == index[1] || index[1] == index[2] || index[0] == index[2];
    return r;
}

// ---- Motion (VK_NV_ray_tracing_motion_blur) ----

namespace {

// The three vertices of triangle t read from `vertexData` (same indexing rules as ClassifyTriangle).
void FetchMotionVertices(const TriangleInput& in, const uint8_t* vertexData, uint32_t t, Vertex v[3], uint64_t index[3]) {
    const unsigned indexBytes = in.indexType == VK_INDEX_TYPE_UINT16 ? 2
                              : in.indexType == VK_INDEX_TYPE_UINT32 ? 4
                              : in.indexType == VK_INDEX_TYPE_NONE_KHR ? 0 : 1;
    for (unsigned k = 0; k < 3; ++k) {
        uint64_t byteOffset;
        if (indexBytes != 0) {
            index[k] = ReadLE(in.indexData + in.primitiveOffset + (3ull * t + k) * indexBytes, indexBytes);
            byteOffset = (index[k] + in.firstVertex) * in.stride;
        } else {
            index[k] = 3ull * t + k;
            byteOffset = in.primitiveOffset + (uint64_t(in.firstVertex) + 3ull * t + k) * in.stride;
        }
        DecodeVertex(in.format, vertexData + byteOffset, &v[k]);
    }
}

bool SameValue(const Component& a, const Component& b) { return !a.nan && !b.nan && a.value == b.value; }

}  // namespace

Triangle ClassifyMotionTriangle(const TriangleInput& in, const uint8_t* vertexData1, uint32_t t) {
    Triangle r;
    Vertex v[2][3];
    uint64_t index[3];
    FetchMotionVertices(in, in.vertexData, t, v[0], index);
    FetchMotionVertices(in, vertexData1, t, v[1], index);
    for (const auto& time : v)
        for (const auto& vert : time) {
            if (vert.c[0].nan) r.active = false;
            r.undefined |= vert.c[1].nan || vert.c[2].nan;
        }
    if (!r.active) { r.undefined = false; return r; }
    // Degenerate at every t: the spec's condition is an "or" of statements, each an "and" of equalities
    // between two components. Component differences interpolate linearly in t, so an equality holds at every
    // t exactly when it holds at both ends. Listing each statement as pairs (vertex a, vertex b, axis):
    struct Eq { int a, b, axis; };
    const Eq statements[6][6] = {
        // "one or more vertices whose respective (X), (Y), (Z) components are identical" (pairs 01, 12, 02)
        {{0, 1, 0}, {0, 1, 1}, {0, 1, 2}, {0, 1, 0}, {0, 1, 0}, {0, 1, 0}},
        {{1, 2, 0}, {1, 2, 1}, {1, 2, 2}, {1, 2, 0}, {1, 2, 0}, {1, 2, 0}},
        {{0, 2, 0}, {0, 2, 1}, {0, 2, 2}, {0, 2, 0}, {0, 2, 0}, {0, 2, 0}},
        // "three vertices that have at least two of the (X), (Y), or (Z) components identical": XY, XZ, YZ
        {{0, 1, 0}, {1, 2, 0}, {0, 1, 1}, {1, 2, 1}, {0, 1, 0}, {0, 1, 0}},
        {{0, 1, 0}, {1, 2, 0}, {0, 1, 2}, {1, 2, 2}, {0, 1, 0}, {0, 1, 0}},
        {{0, 1, 1}, {1, 2, 1}, {0, 1, 2}, {1, 2, 2}, {0, 1, 1}, {0, 1, 1}},
    };
    for (const auto& st : statements) {
        bool always = true;
        for (const Eq& e : st)
            for (const auto& time : v) always &= SameValue(time[e.a].c[e.axis], time[e.b].c[e.axis]);
        r.degenerate |= always;
    }
    if (in.indexType != VK_INDEX_TYPE_NONE_KHR)
        r.sameIndex = index[0] == index[1] || index[1] == index[2] || index[0] == index[2];
    return r;
}

int MotionInstanceActivity(const uint8_t* data, uint32_t primitiveOffset, uint32_t i) {
    const uint8_t* rec = data + primitiveOffset + 160ull * i;
    const uint64_t type = ReadLE(rec, 4);
    // data (the union) follows type and flags at offset 8. Reference offsets from the structure
    // definitions: static = 48-byte transform + 2 x 4-byte bit-field words; matrix = 2 x 48 + 8;
    // SRT = 2 x 64 (16 floats each) + 8.
    const uint64_t at = type == 0 ? 8 + 48 + 8 : type == 1 ? 8 + 96 + 8 : type == 2 ? 8 + 128 + 8 : 0;
    if (at == 0) return -1;
    return ReadLE(rec + at, 8) != 0 ? 1 : 0;
}

}  // namespace oracle
