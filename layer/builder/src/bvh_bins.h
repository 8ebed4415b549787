// Private: the binned SAH builder's bins. A node's references are binned by their doubled centroid
// (lo + hi) on all three axes at once; a bin keeps the box and the count of its references.
#pragma once

#include <emmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "bvh_code.h"

namespace asval::builder::detail {

constexpr uint32_t kMaxBins = 64;

struct Bin {
    __m128 lo, hi;
};

// Maps a doubled centroid to bin coordinates on the three axes at once: t = (c * p - cmin * p) * q,
// clamped to [0, bins - 1]; the bin is trunc(t). p is a power of two keeping tiny (subnormal) and huge
// extents in range; garbage lanes (NaN, inf) clamp and only cost quality.
struct Grid {
    __m128 p, cminp, q, maxBin;
    alignas(16) float lo[4], hi[4];  // the centroid range the grid spans
    alignas(16) float qs[4];         // q per axis; 0: the axis has no extent and is never split

    __m128 Unclamped(__m128 c2) const { return _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(c2, p), cminp), q); }
    __m128 Coord(__m128 c2) const {
        return _mm_min_ps(_mm_max_ps(Unclamped(c2), _mm_setzero_ps()), maxBin);  // NaN -> 0
    }
    // Side of `splitBin` on `axis`: bin < splitBin, i.e. !(t >= splitBin) (t >= 0 after the clamp, NaN
    // clamps to bin 0), the binning's own decision bit for bit. 1: left.
    uint32_t Left(__m128 c2, __m128 splitAt, int axis) const {
        return uint32_t(_mm_movemask_ps(_mm_cmpnge_ps(Unclamped(c2), splitAt)) >> axis) & 1u;
    }
};

inline Grid MakeGrid(const float lo[4], const float hi[4], uint32_t bins) {
    Grid g;
    alignas(16) float p[4] = {1, 1, 1, 1}, cminp[4] = {0, 0, 0, 0};
    for (int a = 0; a < 4; ++a) { g.lo[a] = lo[a]; g.hi[a] = hi[a]; g.qs[a] = 0; }
    for (int a = 0; a < 3; ++a) {
        const double extent = double(hi[a]) - double(lo[a]);
        if (!(extent > 0)) continue;
        p[a] = extent < 1e-30 ? 0x1p100f : (extent > 1e37 ? 0x1p-4f : 1.0f);
        g.qs[a] = float(double(bins) * (1 - 1e-6) / (extent * double(p[a])));
        cminp[a] = lo[a] * p[a];
    }
    g.p = _mm_load_ps(p);
    g.cminp = _mm_load_ps(cminp);
    g.q = _mm_load_ps(g.qs);
    g.maxBin = _mm_set1_ps(float(bins - 1));
    return g;
}

// Adds a reference (box lo/hi) to its bin on each axis; k holds the three bin indices.
inline void AddToBins(Bin* box, uint32_t* count, __m128i k, __m128 lo, __m128 hi, uint32_t bins) {
    const uint32_t k0 = uint32_t(_mm_cvtsi128_si32(k));
    const uint32_t k1 = uint32_t(_mm_cvtsi128_si32(_mm_shuffle_epi32(k, 1))) + bins;
    const uint32_t k2 = uint32_t(_mm_cvtsi128_si32(_mm_shuffle_epi32(k, 2))) + 2 * bins;
    box[k0].lo = _mm_min_ps(box[k0].lo, lo); box[k0].hi = _mm_max_ps(box[k0].hi, hi); ++count[k0];
    box[k1].lo = _mm_min_ps(box[k1].lo, lo); box[k1].hi = _mm_max_ps(box[k1].hi, hi); ++count[k1];
    box[k2].lo = _mm_min_ps(box[k2].lo, lo); box[k2].hi = _mm_max_ps(box[k2].hi, hi); ++count[k2];
}

// One node's bins: per axis, `bins` boxes and counts, on `grid`. `valid` is false until filled.
struct BinSet {
    Grid grid;
    std::unique_ptr<Bin[]> box;  // [axis * bins + k]
    std::unique_ptr<uint32_t[]> count;
    bool valid = false;

    explicit BinSet(uint32_t bins) : box(new Bin[3 * bins]), count(new uint32_t[3 * bins]) {}

    void Reset(const Grid& g, uint32_t bins) {
        grid = g;
        for (uint32_t k = 0; k < 3 * bins; ++k) box[k] = {_mm_set1_ps(INFINITY), _mm_set1_ps(-INFINITY)};
        std::fill(count.get(), count.get() + 3 * bins, 0u);
        valid = true;
    }
    void Add(const PrimRef& ref, __m128 c2, uint32_t bins) {
        AddToBins(box.get(), count.get(), _mm_cvttps_epi32(grid.Coord(c2)), LoadLo(ref), LoadHi(ref), bins);
    }
    // Adds another set on the same grid (min / max / + are exact: the result does not depend on how the
    // references were split between the sets).
    void Merge(const BinSet& o, uint32_t bins) {
        for (uint32_t k = 0; k < 3 * bins; ++k) {
            box[k].lo = _mm_min_ps(box[k].lo, o.box[k].lo);
            box[k].hi = _mm_max_ps(box[k].hi, o.box[k].hi);
            count[k] += o.count[k];
        }
    }

    // Byte image for handing the bins to a spawned task.
    void SaveTo(std::vector<uint8_t>* out, uint32_t bins) const {
        const size_t boxBytes = sizeof(Bin) * 3 * bins, countBytes = sizeof(uint32_t) * 3 * bins;
        out->resize(sizeof(Grid) + boxBytes + countBytes);
        std::memcpy(out->data(), &grid, sizeof(Grid));
        std::memcpy(out->data() + sizeof(Grid), box.get(), boxBytes);
        std::memcpy(out->data() + sizeof(Grid) + boxBytes, count.get(), countBytes);
    }
    void LoadFrom(const std::vector<uint8_t>& in, uint32_t bins) {
        const size_t boxBytes = sizeof(Bin) * 3 * bins, countBytes = sizeof(uint32_t) * 3 * bins;
        std::memcpy(&grid, in.data(), sizeof(Grid));
        std::memcpy(box.get(), in.data() + sizeof(Grid), boxBytes);
        std::memcpy(count.get(), in.data() + sizeof(Grid) + boxBytes, countBytes);
        valid = true;
    }
};

// Running box + centroid box of a set of references.
struct Side {
    __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY);
    __m128 clo = _mm_set1_ps(INFINITY), chi = _mm_set1_ps(-INFINITY);
    void Add(const PrimRef& ref, __m128 c2) {
        lo = _mm_min_ps(lo, LoadLo(ref));
        hi = _mm_max_ps(hi, LoadHi(ref));
        clo = MinKeep(clo, c2);
        chi = MaxKeep(chi, c2);
    }
    void Add(const PrimRef& ref) { Add(ref, Centroid(ref)); }
    void Merge(const Side& o) {  // exact, NaN-free (neither side ever holds a NaN lane)
        lo = _mm_min_ps(lo, o.lo);
        hi = _mm_max_ps(hi, o.hi);
        clo = _mm_min_ps(clo, o.clo);
        chi = _mm_max_ps(chi, o.chi);
    }
    Range ToRange(uint32_t b, uint32_t e, uint32_t depth) const { return Range{b, e, lo, hi, clo, chi, depth}; }
};

inline float Lane(__m128 v, int axis) {
    alignas(16) float f[4];
    _mm_store_ps(f, v);
    return f[axis];
}

}  // namespace asval::builder::detail
