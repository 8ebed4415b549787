// Private: SIMD box helpers and the pieces both build modes share.
#pragma once

#include <emmintrin.h>
#include <xmmintrin.h>
#include <cfloat>
#include <cstdint>
#include <vector>

#include "asval/builder/bvh.h"

namespace asval::builder::detail {

inline __m128 LoadLo(const PrimRef& r) { return _mm_load_ps(r.lo); }  // lane 3 holds the id: ignored
inline __m128 LoadHi(const PrimRef& r) { return _mm_load_ps(r.hi); }

// Twice the centroid (lo + hi): one add. Infinite or huge boxes give +-inf or NaN lanes; every consumer
// tolerates that (min/max keep the running value on NaN, bin indices clamp, such axes fall back to
// median splits), so the common finite case pays nothing for the rare one.
inline __m128 Centroid(const PrimRef& r) { return _mm_add_ps(LoadLo(r), LoadHi(r)); }

// Running min / max that ignore a NaN in `v` (SSE min/max return the second operand on NaN).
inline __m128 MinKeep(__m128 acc, __m128 v) { return _mm_min_ps(v, acc); }
inline __m128 MaxKeep(__m128 acc, __m128 v) { return _mm_max_ps(v, acc); }

// Half surface area in double, coordinates clamped to +-FLT_MAX: finite for any non-NaN box; an empty
// box (lo = +inf, hi = -inf) has area 0.
inline double HalfArea(__m128 lo, __m128 hi) {
    const __m128 big = _mm_set1_ps(FLT_MAX), small = _mm_set1_ps(-FLT_MAX);
    lo = _mm_max_ps(_mm_min_ps(lo, big), small);
    hi = _mm_max_ps(_mm_min_ps(hi, big), small);
    const __m128d zero = _mm_setzero_pd();
    const __m128d e01 = _mm_max_pd(_mm_sub_pd(_mm_cvtps_pd(hi), _mm_cvtps_pd(lo)), zero);
    const __m128d e2 = _mm_max_pd(_mm_sub_pd(_mm_cvtps_pd(_mm_movehl_ps(hi, hi)), _mm_cvtps_pd(_mm_movehl_ps(lo, lo))), zero);
    const double ex = _mm_cvtsd_f64(e01), ey = _mm_cvtsd_f64(_mm_unpackhi_pd(e01, e01)), ez = _mm_cvtsd_f64(e2);
    return ex * ey + ey * ez + ez * ex;
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

}  // namespace asval::builder::detail
