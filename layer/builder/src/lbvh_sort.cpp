// Morton codes and the stable radix sort of the LBVH (see lbvh_sort.h).
#include "lbvh_sort.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstring>

#include "bvh_internal.h"
#include "lbvh_hugepages.h"

namespace asval::builder::detail {
namespace {

// Spreads the low 21 bits of x so that bit i lands on bit 3i.
uint64_t Spread3(uint64_t x) {
    x &= 0x1FFFFFull;
    x = (x | x << 32) & 0x1F00000000FFFFull;
    x = (x | x << 16) & 0x1F0000FF0000FFull;
    x = (x | x << 8) & 0x100F00F00F00F00Full;
    x = (x | x << 4) & 0x10C30C30C30C30C3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

// Spread3 of every 10-bit value: three loads instead of 15 shift/mask steps per code (default 10 bits).
struct SpreadTable {
    std::array<uint32_t, 1024> v;
    SpreadTable() {
        for (uint32_t i = 0; i < 1024; ++i) v[i] = uint32_t(Spread3(i));
    }
};
const SpreadTable& Spread10() {
    static const SpreadTable t;
    return t;
}

// Quantises centroids to the grid: cell = clamp((2 * centroid - lo) * scale, 0, cells), in float SIMD. A
// NaN lane (infinite boxes) becomes cell 0, an infinite one the last cell. Deterministic (no FMA: the
// library is built with -ffp-contract=off).
class Quantizer {
public:
    Quantizer(const std::vector<PrimRef>& refs, uint32_t bitsPerAxis) {
        __m128 clo = _mm_set1_ps(INFINITY), chi = _mm_set1_ps(-INFINITY);
        for (const PrimRef& r : refs) {
            const __m128 c = Centroid(r);
            clo = _mm_min_ps(clo, c);
            chi = _mm_max_ps(chi, c);
        }
        alignas(16) float lo[4], hi[4], scale[4] = {0, 0, 0, 0};
        _mm_store_ps(lo, clo);
        _mm_store_ps(hi, chi);
        const double cells = double((uint64_t(1) << bitsPerAxis) - 1);
        for (int a = 0; a < 3; ++a) {
            const double extent = double(hi[a]) - double(lo[a]);
            // NaN extent (inf - inf): 0; a subnormal extent must not give an infinite scale (0 * inf).
            scale[a] = extent > 0 ? float(std::min(cells / extent, double(FLT_MAX))) : 0.0f;
        }
        lo_ = _mm_load_ps(lo);
        scale_ = _mm_load_ps(scale);
        cells_ = _mm_set1_ps(float(cells));
    }
    // Cell of each axis in lanes 0..2.
    __m128i Cells(const PrimRef& r) const {
        const __m128 q = _mm_mul_ps(_mm_sub_ps(Centroid(r), lo_), scale_);
        // max(q, 0) returns 0 for a NaN q (SSE returns the second operand); min then caps +inf.
        return _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(q, _mm_setzero_ps()), cells_));
    }

private:
    __m128 lo_, scale_, cells_;
};

inline uint32_t Code30(const uint32_t* spread, __m128i cells) {
    alignas(16) uint32_t c[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(c), cells);
    return spread[c[0]] << 2 | spread[c[1]] << 1 | spread[c[2]];
}

inline uint64_t Code63(__m128i cells) {
    alignas(16) uint32_t c[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(c), cells);
    return Spread3(c[0]) << 2 | Spread3(c[1]) << 1 | Spread3(c[2]);
}

// The 30-bit path's working memory is the output array itself: the sorted references take 32 bytes each,
// and the two 8-byte key arrays of the radix sort live in its upper half (keys at byte 16n, their
// ping-pong buffer at 24n). The gather then writes reference i over bytes [32i, 32i + 32), which never
// reach a key it has still to read (key j >= i + 1 sits at 24n + 8j >= 32i + 32). So the sort touches one
// fresh array instead of three (zeroing fresh pages was a fifth of the build). Keys are moved with memcpy:
// the bytes belong to PrimRef objects (trivially copyable).
class SortSpace {
public:
    SortSpace(std::vector<PrimRef>* out, size_t n) : n_(n) {
        ReserveHuge(*out, n);
        out->resize(n);
        bytes_ = reinterpret_cast<unsigned char*>(out->data());
    }
    // Key array 0 at byte 16n, key array 1 at byte 24n.
    uint64_t Key(int array, size_t i) const {
        uint64_t k;
        std::memcpy(&k, bytes_ + (16 + 8 * array) * n_ + 8 * i, 8);
        return k;
    }
    void SetKey(int array, size_t i, uint64_t k) { std::memcpy(bytes_ + (16 + 8 * array) * n_ + 8 * i, &k, 8); }
    void SetRef(size_t i, const PrimRef& r) { std::memcpy(bytes_ + 32 * i, &r, sizeof r); }

private:
    size_t n_;
    unsigned char* bytes_;
};

}  // namespace

void SortByMorton(std::vector<PrimRef>& refs, uint32_t bitsPerAxis, std::vector<uint32_t>* codes,
                  std::vector<uint64_t>* wideCodes) {
    codes->clear();
    wideCodes->clear();
    const uint32_t n = uint32_t(refs.size());
    if (n == 0) return;
    bitsPerAxis = std::clamp<uint32_t>(bitsPerAxis, 1, 21);
    const Quantizer quantize(refs, bitsPerAxis);
    const uint32_t codeBits = 3 * bitsPerAxis;
    if (codeBits <= 32) {
        // 8-byte keys `code << 32 | index`, an LSD radix sort of three digits of ceil(bits / 3) <= 10 bits
        // whose histograms are counted in one pass (10-bit digits: fewer scatter streams than 11).
        constexpr uint32_t kDigits = 3;
        const uint32_t digitBits = (codeBits + kDigits - 1) / kDigits, buckets = 1u << digitBits, mask = buckets - 1;
        std::vector<PrimRef> sorted;
        SortSpace space(&sorted, n);
        std::vector<uint32_t> hist(kDigits * buckets, 0);
        const uint32_t* spread = Spread10().v.data();  // bitsPerAxis <= 10 here
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t code = Code30(spread, quantize.Cells(refs[i]));
            space.SetKey(0, i, uint64_t(code) << 32 | i);
            ++hist[code & mask];
            ++hist[buckets + ((code >> digitBits) & mask)];
            ++hist[2 * buckets + ((code >> (2 * digitBits)) & mask)];
        }
        // Three passes: array 0 -> 1 -> 0 -> 1.
        for (uint32_t d = 0; d < kDigits; ++d) {
            uint32_t* h = &hist[d * buckets];
            uint32_t sum = 0;
            for (uint32_t k = 0; k < buckets; ++k) { const uint32_t c = h[k]; h[k] = sum; sum += c; }
            const unsigned shift = 32 + digitBits * d;
            const int from = int(d & 1), to = 1 - from;
            for (uint32_t i = 0; i < n; ++i) {
                const uint64_t k = space.Key(from, i);
                space.SetKey(to, h[(k >> shift) & mask]++, k);
            }
        }
        // Gather: each reference's load is independent of the others, so many misses overlap.
        ReserveHuge(*codes, n);
        codes->resize(n);
        uint32_t* c = codes->data();
        for (uint32_t i = 0; i < n; ++i) {
            const uint64_t k = space.Key(1, i);
            space.SetRef(i, refs[uint32_t(k)]);
            c[i] = uint32_t(k >> 32);
        }
        refs.swap(sorted);
        return;
    }
    // More than 32 code bits: 16-byte keys, 11-bit digits, codes kept beside the references.
    struct Keyed {
        uint64_t code;
        uint32_t ref;
        uint32_t pad;
    };
    std::vector<Keyed> keys(n), tmp(n);
    for (uint32_t i = 0; i < n; ++i) keys[i] = {Code63(quantize.Cells(refs[i])), i, 0};
    for (uint32_t shift = 0; shift < codeBits; shift += 11) {
        uint32_t hist[2048] = {};
        for (const Keyed& k : keys) ++hist[(k.code >> shift) & 2047];
        uint32_t sum = 0;
        for (uint32_t& h : hist) { const uint32_t c = h; h = sum; sum += c; }
        for (const Keyed& k : keys) tmp[hist[(k.code >> shift) & 2047]++] = k;
        keys.swap(tmp);
    }
    std::vector<Keyed>().swap(tmp);
    {
        std::vector<PrimRef> sorted(n);
        for (uint32_t i = 0; i < n; ++i) sorted[i] = refs[keys[i].ref];
        refs.swap(sorted);
    }
    wideCodes->resize(n);
    for (uint32_t i = 0; i < n; ++i) (*wideCodes)[i] = keys[i].code;
}

}  // namespace asval::builder::detail
