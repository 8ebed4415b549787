// Private: SIMD box helpers and the pieces both build modes share.
#pragma once

#include <xmmintrin.h>
#include <cfloat>
#include <cstdint>
#include <vector>

#include "asval/builder/bvh.h"

namespace asval::builder::detail {

inline __m128 LoadLo(const PrimRef& r) { return _mm_load_ps(r.lo); }  // lane 3 holds the id: ignored
inline __m128 LoadHi(const PrimRef& r) { return _mm_load_ps(r.hi); }

// Centroid with coordinates clamped to +-FLT_MAX, so infinite boxes still have a finite centroid.
inline __m128 Centroid(const PrimRef& r) {
    const __m128 big = _mm_set1_ps(FLT_MAX), small = _mm_set1_ps(-FLT_MAX), half = _mm_set1_ps(0.5f);
    const __m128 lo = _mm_max_ps(_mm_min_ps(LoadLo(r), big), small);
    const __m128 hi = _mm_max_ps(_mm_min_ps(LoadHi(r), big), small);
    return _mm_add_ps(_mm_mul_ps(lo, half), _mm_mul_ps(hi, half));
}

// Half surface area in double, coordinates clamped to +-FLT_MAX: finite for any non-NaN box.
inline double HalfArea(__m128 lo, __m128 hi) {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo);
    _mm_store_ps(h, hi);
    double e[3];
    for (int i = 0; i < 3; ++i) {
        const double a = l[i] < -FLT_MAX ? -FLT_MAX : (l[i] > FLT_MAX ? FLT_MAX : l[i]);
        const double b = h[i] < -FLT_MAX ? -FLT_MAX : (h[i] > FLT_MAX ? FLT_MAX : h[i]);
        e[i] = b > a ? b - a : 0.0;
    }
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

inline void StoreNodeBox(BvhNode& n, __m128 lo, __m128 hi) {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo);
    _mm_store_ps(h, hi);
    for (int i = 0; i < 3; ++i) { n.lo[i] = l[i]; n.hi[i] = h[i]; }
}

// Levels needed to bring `count` references down to leaves of `maxLeaf` by halving.
inline uint32_t HalvingLevels(uint32_t count, uint32_t maxLeaf) {
    uint32_t levels = 0;
    for (uint64_t c = count; c > maxLeaf; c = (c + 1) / 2) ++levels;
    return levels;
}

constexpr uint32_t kMaxDepth = 64;  // nodes on the longest root-to-leaf path

Bvh BuildBinnedSah(std::vector<PrimRef>& refs, const BuildOptions& options);
Bvh BuildLbvh(std::vector<PrimRef>& refs, const BuildOptions& options);
void FillStats(Bvh& bvh);

}  // namespace asval::builder::detail
