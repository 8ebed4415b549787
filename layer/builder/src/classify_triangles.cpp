// Triangle classification: the activity pass. One loop per (vertex format, index type), instantiated from
// small traits so that the inner loop has no per-vertex switch. Hot path: no allocation except the
// record's bitset (reused when large enough), no floating-point arithmetic before the NaN test.
#include <emmintrin.h>

#include <algorithm>
#include <cstring>
#include <type_traits>

#include "asval/builder/classify.h"
#include "asval/builder/index_hash.h"
#include "asval/builder/vertex_format.h"
#include "format_traits.h"
#include "motion_triangles.h"
#include "float_mode.h"

namespace asval::builder {
namespace {

using namespace detail;

// Component keys of one vertex (see format_traits.h) plus the NaN flags of its source bits.
struct VertexKeys {
    uint32_t k[3];
    bool xNaN;
    bool yzNaN;
};

template <ComponentKind K, unsigned Bits, bool HasZ>
struct Fmt;

template <bool HasZ>
struct Fmt<ComponentKind::Float32, 32, HasZ> {
    static constexpr bool kHasNaN = true;
    static VertexKeys Load(const uint8_t* p) {
        const uint32_t x = LoadU32(p), y = LoadU32(p + 4), z = HasZ ? LoadU32(p + 8) : 0u;
        return {{F32Key(x), F32Key(y), F32Key(z)}, F32BitsNaN(x), F32BitsNaN(y) || F32BitsNaN(z)};
    }
    static constexpr unsigned kLoadBytes = HasZ ? 16 : 8;
    static __m128i Keys(const uint8_t* p, int* nanBits) {
        __m128i v = HasZ ? _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)), _mm_set_epi32(0, -1, -1, -1))
                         : _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p));
        const __m128i magnitude = _mm_and_si128(v, _mm_set1_epi32(0x7FFFFFFF));
        *nanBits = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(magnitude, _mm_set1_epi32(0x7F800000))));
        // -0 -> +0: clear the sign where the magnitude is zero.
        const __m128i zero = _mm_cmpeq_epi32(magnitude, _mm_setzero_si128());
        return _mm_andnot_si128(_mm_and_si128(zero, _mm_set1_epi32(int32_t(0x80000000u))), v);
    }
};

// Loads the first 2 (HasZ: 3) 16-bit components into 32-bit lanes, zero-extended, other lanes 0.
template <bool HasZ>
inline __m128i Load16x3(const uint8_t* p) {
    const __m128i v = HasZ ? _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)) : _mm_cvtsi32_si128(int32_t(LoadU32(p)));
    const __m128i lanes = _mm_unpacklo_epi16(v, _mm_setzero_si128());
    return HasZ ? _mm_and_si128(lanes, _mm_set_epi32(0, -1, -1, -1)) : lanes;
}

template <bool HasZ>
struct Fmt<ComponentKind::Float16, 16, HasZ> {
    static constexpr bool kHasNaN = true;
    static VertexKeys Load(const uint8_t* p) {
        const uint32_t x = LoadU16(p), y = LoadU16(p + 2), z = HasZ ? LoadU16(p + 4) : 0u;
        return {{F16Key(x), F16Key(y), F16Key(z)}, F16BitsNaN(x), F16BitsNaN(y) || F16BitsNaN(z)};
    }
    static constexpr unsigned kLoadBytes = HasZ ? 8 : 4;
    static __m128i Keys(const uint8_t* p, int* nanBits) {
        const __m128i v = Load16x3<HasZ>(p);
        const __m128i magnitude = _mm_and_si128(v, _mm_set1_epi32(0x7FFF));
        *nanBits = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(magnitude, _mm_set1_epi32(0x7C00))));
        return _mm_andnot_si128(_mm_cmpeq_epi32(magnitude, _mm_setzero_si128()), v);  // -0 -> 0
    }
};

template <unsigned Bits, bool HasZ>
struct Fmt<ComponentKind::Snorm, Bits, HasZ> {
    static constexpr bool kHasNaN = false;
    static int32_t Code(const uint8_t* p, int c) {
        if constexpr (Bits == 8) return int8_t(p[c]);
        else return int16_t(LoadU16(p + 2 * c));
    }
    static VertexKeys Load(const uint8_t* p) {
        return {{SnormKey(Code(p, 0), Bits), SnormKey(Code(p, 1), Bits), HasZ ? SnormKey(Code(p, 2), Bits) : 0u},
                false, false};
    }
    static constexpr unsigned kLoadBytes = Bits == 16 ? (HasZ ? 8 : 4) : 4;
    static __m128i Keys(const uint8_t* p, int* nanBits) {
        *nanBits = 0;
        __m128i v16;  // sign-extended 16-bit codes in the low 64 bits
        if constexpr (Bits == 16) {
            v16 = HasZ ? _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)) : _mm_cvtsi32_si128(int32_t(LoadU32(p)));
        } else {
            const __m128i b = _mm_cvtsi32_si128(int32_t(HasZ ? LoadU32(p) : LoadU16(p)));
            v16 = _mm_srai_epi16(_mm_unpacklo_epi8(b, b), 8);
        }
        // The clamp max(c, -(2^(b-1)-1)) makes the two codes of -1 one key (value equality).
        v16 = _mm_max_epi16(v16, _mm_set1_epi16(int16_t(-((1 << (Bits - 1)) - 1))));
        const __m128i lanes = _mm_unpacklo_epi16(v16, _mm_setzero_si128());  // key = 16-bit pattern
        return _mm_and_si128(lanes, HasZ ? _mm_set_epi32(0, -1, -1, -1) : _mm_set_epi32(0, 0, -1, -1));
    }
};

template <unsigned Bits, bool HasZ>
struct Fmt<ComponentKind::Unorm, Bits, HasZ> {
    static constexpr bool kHasNaN = false;
    static uint32_t Code(const uint8_t* p, int c) {
        if constexpr (Bits == 8) return p[c];
        else return LoadU16(p + 2 * c);
    }
    static VertexKeys Load(const uint8_t* p) {
        return {{Code(p, 0), Code(p, 1), HasZ ? Code(p, 2) : 0u}, false, false};
    }
    static constexpr unsigned kLoadBytes = Bits == 16 ? (HasZ ? 8 : 4) : 4;
    static __m128i Keys(const uint8_t* p, int* nanBits) {
        *nanBits = 0;
        if constexpr (Bits == 16) {
            return Load16x3<HasZ>(p);
        } else {
            const __m128i b = _mm_cvtsi32_si128(int32_t(HasZ ? LoadU32(p) : LoadU16(p)));
            const __m128i lanes = _mm_unpacklo_epi16(_mm_unpacklo_epi8(b, _mm_setzero_si128()), _mm_setzero_si128());
            return _mm_and_si128(lanes, HasZ ? _mm_set_epi32(0, -1, -1, -1) : _mm_set_epi32(0, 0, -1, -1));
        }
    }
};

template <bool HasZ>
struct Fmt<ComponentKind::Unorm1010102, 10, HasZ> {
    static constexpr bool kHasNaN = false;
    static VertexKeys Load(const uint8_t* p) {
        const uint32_t w = LoadU32(p);
        return {{w & 0x3FFu, (w >> 10) & 0x3FFu, (w >> 20) & 0x3FFu}, false, false};
    }
    static constexpr unsigned kLoadBytes = 4;
    static __m128i Keys(const uint8_t* p, int* nanBits) {
        *nanBits = 0;
        const uint32_t w = LoadU32(p);
        return _mm_set_epi32(0, int32_t((w >> 20) & 0x3FFu), int32_t((w >> 10) & 0x3FFu), int32_t(w & 0x3FFu));
    }
};

// The spec's definition, on keys: two vertices identical, or all three sharing >= 2 of X, Y, Z.
inline bool DegenerateKeys(const VertexKeys& a, const VertexKeys& b, const VertexKeys& c) {
    const bool sx01 = a.k[0] == b.k[0], sy01 = a.k[1] == b.k[1], sz01 = a.k[2] == b.k[2];
    const bool sx12 = b.k[0] == c.k[0], sy12 = b.k[1] == c.k[1], sz12 = b.k[2] == c.k[2];
    const bool sx02 = a.k[0] == c.k[0], sy02 = a.k[1] == c.k[1], sz02 = a.k[2] == c.k[2];
    const bool same01 = sx01 & sy01 & sz01, same12 = sx12 & sy12 & sz12, same02 = sx02 & sy02 & sz02;
    const int axes = int(sx01 & sx12) + int(sy01 & sy12) + int(sz01 & sz12);
    return same01 | same12 | same02 | (axes >= 2);
}

// The same definition on SIMD keys: lane masks of equal components per vertex pair.
inline bool DegenerateSimd(__m128i a, __m128i b, __m128i c) {
    const int m01 = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(a, b))) & 7;
    const int m12 = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(b, c))) & 7;
    const int m02 = _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(a, c))) & 7;
    // Axes shared by all three vertices: m01 & m12 (key equality is transitive); >= 2 of them: 0xE8 table.
    return (m01 == 7) | (m12 == 7) | (m02 == 7) | ((0xE8 >> (m01 & m12)) & 1);
}

// Undefined-input triangles (NaN in Y/Z) take this path: value comparison on decoded floats, where NaN
// is unequal to everything (IEEE ==; this file is never built with -ffast-math).
bool DegenerateDecoded(const VertexFormatInfo& info, const uint8_t* p0, const uint8_t* p1, const uint8_t* p2) {
    float a[3], b[3], c[3];
    DecodeVertex(info, p0, a);
    DecodeVertex(info, p1, b);
    DecodeVertex(info, p2, c);
    bool sameAB = true, sameBC = true, sameAC = true;
    int axes = 0;
    for (int i = 0; i < 3; ++i) {
        sameAB &= a[i] == b[i];
        sameBC &= b[i] == c[i];
        sameAC &= a[i] == c[i];
        axes += (a[i] == b[i] && b[i] == c[i]) ? 1 : 0;
    }
    return sameAB || sameBC || sameAC || axes >= 2;
}

struct NoIndex {};

template <typename IndexT>
inline uint64_t LoadIndex(const uint8_t* p, uint64_t i) {
    if constexpr (sizeof(IndexT) == 1) return p[i];
    else if constexpr (sizeof(IndexT) == 2) return LoadU16(p + 2 * i);
    else return LoadU32(p + 4 * i);
}

struct Counters {
    uint32_t active = 0, degenerate = 0, sameIndex = 0, undefinedNaN = 0, unreadable = 0, overMaxVertex = 0;
    uint32_t firstUndefined = UINT32_MAX, firstUnreadable = UINT32_MAX, firstOverMaxVertex = UINT32_MAX;
};

struct LoopInput {
    const VertexFormatInfo* info;
    const uint8_t* vertices;
    uint64_t readableVertices;  // vertex v is readable iff v < readableVertices (indexed: from vertexData)
    uint64_t availableBytes;    // bytes readable from `vertices` (for the wider SIMD loads)
    uint64_t stride;
    uint64_t maxVertex;
    uint64_t firstVertex;
    const uint8_t* indices;     // already advanced by primitiveOffset
    uint32_t count;             // triangles
    uint32_t begin, end;        // the chunk this call classifies (begin % 64 == 0)
    uint32_t readableCount;     // triangles whose indices (or vertices, non-indexed) were provided
    uint64_t* bits;             // may be null
    uint8_t* states;            // may be null
};

template <typename F, typename IndexT>
void ClassifyLoop(const LoopInput& in, Counters& out) {
    constexpr bool kIndexed = !std::is_same_v<IndexT, NoIndex>;
    const uint64_t simdVertices =
        std::min(in.readableVertices, in.availableBytes < F::kLoadBytes ? 0
                                      : in.stride == 0 ? UINT64_MAX
                                                       : (in.availableBytes - F::kLoadBytes) / in.stride + 1);
    uint64_t word = 0;
    for (uint32_t t = in.begin; t < in.end; ++t) {
        uint64_t v0 = 0, v1 = 0, v2 = 0;
        const bool indicesReadable = t < in.readableCount;  // checked before any index is loaded
        if constexpr (kIndexed) {
            if (__builtin_expect(indicesReadable, 1)) {
                v0 = LoadIndex<IndexT>(in.indices, 3ull * t) + in.firstVertex;
                v1 = LoadIndex<IndexT>(in.indices, 3ull * t + 1) + in.firstVertex;
                v2 = LoadIndex<IndexT>(in.indices, 3ull * t + 2) + in.firstVertex;
            }
        } else {
            v0 = 3ull * t; v1 = v0 + 1; v2 = v0 + 2;
        }
        const uint64_t vmax = std::max(v0, std::max(v1, v2));
        uint8_t state;
        if (__builtin_expect(!indicesReadable || vmax >= in.readableVertices, 0)) {
            // Not provided: cannot be classified; recorded active so no update error is invented from it.
            state = kStateActive | kStateUnreadable;
            ++out.unreadable;
            if (out.firstUnreadable == UINT32_MAX) out.firstUnreadable = t;
        } else {
            const uint8_t* p0 = in.vertices + v0 * in.stride;
            const uint8_t* p1 = in.vertices + v1 * in.stride;
            const uint8_t* p2 = in.vertices + v2 * in.stride;
            bool inactive, undefinedInput, degenerate = false;
            __m128i ka = _mm_setzero_si128(), kb = ka, kc = ka;  // set on the wide path only
            const bool wide = vmax < simdVertices;  // the SIMD loads read kLoadBytes: only where provided
            if (__builtin_expect(wide, 1)) {
                int na, nb, nc;
                ka = F::Keys(p0, &na);
                kb = F::Keys(p1, &nb);
                kc = F::Keys(p2, &nc);
                const int nan = na | nb | nc;
                inactive = F::kHasNaN && (nan & 1);
                undefinedInput = F::kHasNaN && (nan & 6);
            } else {
                const VertexKeys a = F::Load(p0), b = F::Load(p1), c = F::Load(p2);
                inactive = F::kHasNaN && (a.xNaN | b.xNaN | c.xNaN);
                undefinedInput = F::kHasNaN && (a.yzNaN | b.yzNaN | c.yzNaN);
                if (!inactive && !undefinedInput) degenerate = DegenerateKeys(a, b, c);
            }
            if (inactive) {
                state = 0;
            } else {
                if (__builtin_expect(undefinedInput, 0)) {
                    degenerate = DegenerateDecoded(*in.info, p0, p1, p2);
                    ++out.undefinedNaN;
                    if (out.firstUndefined == UINT32_MAX) out.firstUndefined = t;
                } else if (wide) {
                    degenerate = DegenerateSimd(ka, kb, kc);
                }
                bool sameIndex = false;
                if constexpr (kIndexed) sameIndex = (v0 == v1) | (v1 == v2) | (v0 == v2);
                state = uint8_t(kStateActive | (degenerate ? kStateDegenerate : 0) |
                                (sameIndex ? kStateSameIndex : 0) | (undefinedInput ? kStateUndefined : 0));
                out.degenerate += degenerate;
                out.sameIndex += sameIndex;
            }
        }
        if (__builtin_expect(indicesReadable && vmax > in.maxVertex, 0)) {
            ++out.overMaxVertex;
            if (out.firstOverMaxVertex == UINT32_MAX) out.firstOverMaxVertex = t;
        }
        const uint64_t activeBit = state & kStateActive;
        out.active += uint32_t(activeBit);
        word |= activeBit << (t & 63);
        if ((t & 63) == 63) {
            if (in.bits) in.bits[t >> 6] = word;
            word = 0;
        }
        if (in.states) in.states[t] = state;
    }
    if (in.end == in.count && (in.count & 63) != 0 && in.bits) in.bits[in.count >> 6] = word;
}

using LoopFn = void (*)(const LoopInput&, Counters&);

template <typename F>
LoopFn PickIndex(int indexBytes) {
    switch (indexBytes) {
        case 0: return &ClassifyLoop<F, NoIndex>;
        case 1: return &ClassifyLoop<F, uint8_t>;
        case 2: return &ClassifyLoop<F, uint16_t>;
        default: return &ClassifyLoop<F, uint32_t>;
    }
}

LoopFn PickLoop(const VertexFormatInfo& f, int indexBytes) {
    const bool z = f.componentCount >= 3;
    switch (f.kind) {
        case ComponentKind::Float32:
            return z ? PickIndex<Fmt<ComponentKind::Float32, 32, true>>(indexBytes)
                     : PickIndex<Fmt<ComponentKind::Float32, 32, false>>(indexBytes);
        case ComponentKind::Float16:
            return z ? PickIndex<Fmt<ComponentKind::Float16, 16, true>>(indexBytes)
                     : PickIndex<Fmt<ComponentKind::Float16, 16, false>>(indexBytes);
        case ComponentKind::Snorm:
            if (f.componentBits == 8)
                return z ? PickIndex<Fmt<ComponentKind::Snorm, 8, true>>(indexBytes)
                         : PickIndex<Fmt<ComponentKind::Snorm, 8, false>>(indexBytes);
            return z ? PickIndex<Fmt<ComponentKind::Snorm, 16, true>>(indexBytes)
                     : PickIndex<Fmt<ComponentKind::Snorm, 16, false>>(indexBytes);
        case ComponentKind::Unorm:
            if (f.componentBits == 8)
                return z ? PickIndex<Fmt<ComponentKind::Unorm, 8, true>>(indexBytes)
                         : PickIndex<Fmt<ComponentKind::Unorm, 8, false>>(indexBytes);
            return z ? PickIndex<Fmt<ComponentKind::Unorm, 16, true>>(indexBytes)
                     : PickIndex<Fmt<ComponentKind::Unorm, 16, false>>(indexBytes);
        case ComponentKind::Unorm1010102:
            return PickIndex<Fmt<ComponentKind::Unorm1010102, 10, true>>(indexBytes);
    }
    return nullptr;
}

// Number of whole elements of `elementBytes`, `stride` apart, readable from byte `offset` of a block of
// `bytes` (stride 0: all of them, if one is readable). Overflow-safe.
uint64_t ReadableElements(uint64_t bytes, uint64_t offset, uint64_t elementBytes, uint64_t stride) {
    if (offset > bytes || bytes - offset < elementBytes) return 0;
    if (stride == 0) return UINT64_MAX;
    return (bytes - offset - elementBytes) / stride + 1;
}

// Activity only (ClassifyDetail::kActivity): whether every triangle of the range is readable and no vertex any
// of them can read holds a NaN in X, Y or Z, so that each is active with defined input and the per-triangle loop
// can be skipped. Reads the indices once (their smallest and largest value) and the vertices between those
// once, instead of three vertices per triangle. False (the loop decides) whenever that is not certain, and when
// the vertices between would outnumber the triangles' three (a sparse range of a large shared buffer).
template <typename IndexT>
void IndexRange(const uint8_t* indices, uint64_t count, uint64_t* lo, uint64_t* hi) {
    uint32_t mn = UINT32_MAX, mx = 0;
    for (uint64_t i = 0; i < count; ++i) {
        const uint32_t v = uint32_t(LoadIndex<IndexT>(indices, i));
        mn = v < mn ? v : mn;
        mx = v > mx ? v : mx;
    }
    *lo = mn;
    *hi = mx;
}

// The same for 32-bit indices, four at a time (SSE2 compares are signed: the values are biased by the sign bit),
// the rest one at a time.
template <>
void IndexRange<uint32_t>(const uint8_t* indices, uint64_t count, uint64_t* lo, uint64_t* hi) {
    const __m128i bias = _mm_set1_epi32(INT32_MIN);
    __m128i mn = _mm_set1_epi32(INT32_MAX), mx = bias;  // UINT32_MAX and 0, biased
    uint64_t i = 0;
    for (; i + 4 <= count; i += 4) {
        const __m128i v = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(indices + 4 * i)), bias);
        const __m128i below = _mm_cmplt_epi32(v, mn), above = _mm_cmpgt_epi32(v, mx);
        mn = _mm_or_si128(_mm_and_si128(below, v), _mm_andnot_si128(below, mn));
        mx = _mm_or_si128(_mm_and_si128(above, v), _mm_andnot_si128(above, mx));
    }
    uint32_t lanesMn[4], lanesMx[4];
    _mm_storeu_si128(reinterpret_cast<__m128i*>(lanesMn), _mm_xor_si128(mn, bias));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(lanesMx), _mm_xor_si128(mx, bias));
    IndexRange<uint8_t>(nullptr, 0, lo, hi);  // the empty range: lo UINT32_MAX, hi 0
    for (int k = 0; k < 4; ++k) {
        *lo = std::min<uint64_t>(*lo, lanesMn[k]);
        *hi = std::max<uint64_t>(*hi, lanesMx[k]);
    }
    for (; i < count; ++i) {
        *lo = std::min<uint64_t>(*lo, LoadU32(indices + 4 * i));
        *hi = std::max<uint64_t>(*hi, LoadU32(indices + 4 * i));
    }
}

// 16-bit indices eight at a time, biased as above.
template <>
void IndexRange<uint16_t>(const uint8_t* indices, uint64_t count, uint64_t* lo, uint64_t* hi) {
    const __m128i bias = _mm_set1_epi16(INT16_MIN);
    __m128i mn = _mm_set1_epi16(INT16_MAX), mx = bias;
    uint64_t i = 0;
    for (; i + 8 <= count; i += 8) {
        const __m128i v = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(indices + 2 * i)), bias);
        mn = _mm_min_epi16(mn, v);
        mx = _mm_max_epi16(mx, v);
    }
    uint16_t lanesMn[8], lanesMx[8];
    _mm_storeu_si128(reinterpret_cast<__m128i*>(lanesMn), _mm_xor_si128(mn, bias));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(lanesMx), _mm_xor_si128(mx, bias));
    IndexRange<uint8_t>(nullptr, 0, lo, hi);
    for (int k = 0; k < 8; ++k) {
        *lo = std::min<uint64_t>(*lo, lanesMn[k]);
        *hi = std::max<uint64_t>(*hi, lanesMx[k]);
    }
    for (; i < count; ++i) {
        *lo = std::min<uint64_t>(*lo, LoadU16(indices + 2 * i));
        *hi = std::max<uint64_t>(*hi, LoadU16(indices + 2 * i));
    }
}

// Whether a component of vertices first..last, up to Z, is NaN (each vertex read at `stride`). Word is the
// component's bits (uint32_t: float32, uint16_t: float16).
template <typename Word, unsigned Components>
bool AnyNaN(const uint8_t* vertices, uint64_t stride, uint64_t first, uint64_t last) {
    constexpr Word kMagnitude = sizeof(Word) == 4 ? Word(0x7FFFFFFFu) : Word(0x7FFFu);
    constexpr Word kInfinity = sizeof(Word) == 4 ? Word(0x7F800000u) : Word(0x7C00u);
    const uint8_t* from = vertices + first * stride;
    if (stride % sizeof(Word) != 0 || stride > 16) {
        Word largest = 0;  // the largest magnitude bits: NaN iff above infinity's
        for (uint64_t v = first; v <= last; ++v) {
            for (unsigned c = 0; c < Components; ++c) {
                Word w;
                std::memcpy(&w, vertices + v * stride + sizeof(Word) * c, sizeof(Word));
                w &= kMagnitude;
                largest = w > largest ? w : largest;
            }
        }
        return largest > kInfinity;
    }
    // Vertices at most 16 bytes apart, each component on a word boundary: every word from the first vertex's X
    // to the last one's last component is tested, 16 bytes at a time. The words between vertices (padding, other
    // attributes) are tested too: a NaN there sends the caller to the loop, which tests exactly what is read.
    const uint64_t bytes = (last - first) * stride + sizeof(Word) * Components;
    const bool wide = sizeof(Word) == 4;
    const __m128i magnitude = wide ? _mm_set1_epi32(int32_t(kMagnitude)) : _mm_set1_epi16(int16_t(kMagnitude));
    const __m128i infinity = wide ? _mm_set1_epi32(int32_t(kInfinity)) : _mm_set1_epi16(int16_t(kInfinity));
    __m128i nan = _mm_setzero_si128();
    uint64_t i = 0;
    for (; i + 16 <= bytes; i += 16) {
        const __m128i m = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(from + i)), magnitude);
        nan = _mm_or_si128(nan, wide ? _mm_cmpgt_epi32(m, infinity) : _mm_cmpgt_epi16(m, infinity));
    }
    bool any = _mm_movemask_epi8(nan) != 0;
    for (; i < bytes; i += sizeof(Word)) {
        Word w;
        std::memcpy(&w, from + i, sizeof(Word));
        any |= Word(w & kMagnitude) > kInfinity;
    }
    return any;
}

bool EveryTriangleActive(const LoopInput& in, int indexBytes) {
    const uint64_t n = in.count;
    if (n == 0 || in.readableCount < n) return false;
    uint64_t lo = 0, hi = 3 * n - 1;  // non-indexed: vertex j of the range for j < 3n
    if (indexBytes == 1) IndexRange<uint8_t>(in.indices, 3 * n, &lo, &hi);
    else if (indexBytes == 2) IndexRange<uint16_t>(in.indices, 3 * n, &lo, &hi);
    else if (indexBytes == 4) IndexRange<uint32_t>(in.indices, 3 * n, &lo, &hi);
    lo += in.firstVertex;  // indexed: firstVertex is added to each index (0 otherwise)
    hi += in.firstVertex;
    if (hi >= in.readableVertices) return false;  // some triangle is unreadable
    const VertexFormatInfo& f = *in.info;
    if (!f.hasNaN) return true;
    if (hi - lo >= 3 * n) return false;
    const bool z = f.componentCount >= 3;
    const uint8_t* v = in.vertices;
    if (f.kind == ComponentKind::Float32)
        return z ? !AnyNaN<uint32_t, 3>(v, in.stride, lo, hi) : !AnyNaN<uint32_t, 2>(v, in.stride, lo, hi);
    if (f.kind == ComponentKind::Float16)
        return z ? !AnyNaN<uint16_t, 3>(v, in.stride, lo, hi) : !AnyNaN<uint16_t, 2>(v, in.stride, lo, hi);
    return false;
}

}  // namespace

ClassifyResult ClassifyTriangles(const TriangleGeometryView& view, ActivityRecord* record, uint8_t* states,
                                 ClassifyDetail detail) {
    const detail::FloatModeGuard mode;
    if (view.motionVertexData) return detail::ClassifyMotionTriangles(view, record, states);  // motion_triangles.cpp
    ClassifyResult r;
    const uint32_t n = view.range.primitiveCount;
    r.primitiveCount = n;
    const VertexFormatInfo* info = FindVertexFormat(view.vertexFormat);
    if (!info) { r.status = ClassifyStatus::UnsupportedFormat; return r; }
    const int indexBytes = IndexTypeBytes(view.indexType);
    if (indexBytes < 0) { r.status = ClassifyStatus::UnsupportedIndexType; return r; }

    if (view.transformData) {
        const uint64_t off = view.range.transformOffset;
        if (off > view.transformDataBytes || view.transformDataBytes - off < 48) {
            r.transformUnreadable = true;
        } else {
            const auto* m = static_cast<const uint8_t*>(view.transformData) + off;
            for (int i = 0; i < 12; ++i) r.transformHasNaN |= F32BitsNaN(LoadU32(m + 4 * i));
        }
    }

    LoopInput in{};
    in.info = info;
    in.stride = view.vertexStride;
    in.maxVertex = view.maxVertex;
    in.count = n;
    if (record) {
        record->activeBits.resize((size_t(n) + 63) / 64);
        in.bits = record->activeBits.data();
    }
    in.states = states;
    const uint64_t vertexBytes = view.vertexData ? view.vertexDataBytes : 0;
    if (indexBytes == 0) {
        // Non-indexed: vertex j of the range sits at primitiveOffset + stride * (firstVertex + j).
        const uint64_t base = uint64_t(view.range.primitiveOffset) + view.vertexStride * view.range.firstVertex;
        in.vertices = static_cast<const uint8_t*>(view.vertexData) + (base <= vertexBytes ? base : 0);
        in.readableVertices = ReadableElements(vertexBytes, base, info->vertexBytes, view.vertexStride);
        in.availableBytes = base <= vertexBytes ? vertexBytes - base : 0;
        in.readableCount = n;
        // The loop sees vertex j of the range; it reads vertex firstVertex + j, so shift maxVertex (when
        // firstVertex already exceeds it, 0 makes every triangle count, as vmax >= 2).
        in.maxVertex = view.maxVertex >= view.range.firstVertex ? view.maxVertex - view.range.firstVertex : 0;
    } else {
        in.vertices = static_cast<const uint8_t*>(view.vertexData);
        in.readableVertices = ReadableElements(vertexBytes, 0, info->vertexBytes, view.vertexStride);
        in.availableBytes = vertexBytes;
        in.firstVertex = view.range.firstVertex;
        const uint64_t off = view.range.primitiveOffset;
        const uint64_t indexAvail = view.indexData ? view.indexDataBytes : 0;
        const uint64_t triBytes = 3ull * uint64_t(indexBytes);
        const uint64_t readable = off <= indexAvail ? (indexAvail - off) / triBytes : 0;
        in.readableCount = uint32_t(std::min<uint64_t>(readable, n));
        in.indices = static_cast<const uint8_t*>(view.indexData) + (off <= indexAvail ? off : 0);
        r.indexHashPartial = in.readableCount < n;
    }
    if (!in.vertices) in.readableVertices = 0;

    // Chunks of 4096 triangles (a multiple of 64 bits and of the hash's 64-triangle blocks): each chunk's indices
    // are hashed right after they were classified, while still in cache.
    constexpr uint32_t kChunk = 4096;
    static_assert(kChunk % kIndexHashBlockTriangles == 0, "a chunk holds whole blocks of the index hash");
    const bool hashing = record && indexBytes != 0;
    IndexHashCombiner hasher{uint64_t(indexBytes)};
    const uint64_t hashBytes = hashing ? uint64_t(in.readableCount) * 3u * uint64_t(indexBytes) : 0;
    Counters c;
    // Activity only, every triangle active and readable: the bits set at once, the indices hashed in one go.
    const bool allActive = detail == ClassifyDetail::kActivity && !states && EveryTriangleActive(in, indexBytes);
    if (allActive) {
        c.active = n;
        if (in.bits) {
            std::fill(in.bits, in.bits + n / 64, ~uint64_t{0});
            if (n % 64 != 0) in.bits[n / 64] = (uint64_t{1} << (n % 64)) - 1;
        }
        if (hashing) hasher.AddBlocks(in.indices, size_t(hashBytes));
    }
    const LoopFn loop = PickLoop(*info, indexBytes);
    for (uint32_t begin = 0; begin < (allActive ? 0 : n); begin += kChunk) {
        in.begin = begin;
        in.end = n - begin > kChunk ? begin + kChunk : n;
        loop(in, c);
        if (hashing) {
            const uint64_t from = uint64_t(begin) * 3u * uint64_t(indexBytes);
            const uint64_t to = std::min<uint64_t>(uint64_t(in.end) * 3u * uint64_t(indexBytes), hashBytes);
            if (to > from) hasher.AddBlocks(in.indices + from, size_t(to - from));
        }
    }
    if (hashing) {
        record->hasIndexHash = true;
        record->indexHash = hasher.Finish(hashBytes);
    }

    r.active = c.active;
    r.inactive = n - c.active;
    r.degenerate = c.degenerate;
    r.sameIndex = c.sameIndex;
    r.undefinedNaN = c.undefinedNaN;
    r.unreadable = c.unreadable;
    r.overMaxVertex = c.overMaxVertex;
    r.firstUndefined = c.firstUndefined;
    r.firstUnreadable = c.firstUnreadable;
    r.firstOverMaxVertex = c.firstOverMaxVertex;
    if (record) {
        record->primitiveCount = n;
        record->activeCount = c.active;
        if (indexBytes == 0) { record->hasIndexHash = false; record->indexHash = {}; }
    }
    return r;
}

}  // namespace asval::builder
