// Exact splits of small nodes (see bvh_small_splits.h). Nodes this small are most of the binned SAH
// builder's nodes (about 0.9 per reference), so both paths avoid per-element work beyond the minimum:
// centroids are computed once, and nodes of at most 5 references skip sorting altogether.
#include "bvh_small_splits.h"

#include <algorithm>
#include <cmath>

#include "bvh_bins.h"

namespace asval::builder::detail {
namespace {

// Bits set in a mask below 2^kExhaustiveMax (the portable builtin becomes a library call without
// -mpopcnt, which this library does not assume).
uint32_t PopCount5(uint32_t m) {
    static_assert(kExhaustiveMax <= 5, "table size");
    static constexpr uint8_t kBits[32] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4,
                                          1, 2, 2, 3, 2, 3, 3, 4, 2, 3, 3, 4, 3, 4, 4, 5};
    return kBits[m];
}

Range WithCentroids(PrimRef* refs, uint32_t begin, uint32_t end, __m128 lo, __m128 hi, uint32_t depth) {
    Side s;
    for (uint32_t i = begin; i < end; ++i) s.Add(refs[i]);
    return Range{begin, end, lo, hi, s.clo, s.chi, depth};
}

// Every bipartition (a superset of the sweep's candidates): the boxes of all 2^n subsets are built
// incrementally, each from a smaller one.
bool BestSubsetSplit(PrimRef* allRefs, const Range& r, double* bestCost, Range* left, Range* right) {
    const uint32_t count = r.end - r.begin;
    PrimRef* const refs = allRefs + r.begin;
    const uint32_t full = (1u << count) - 1;
    __m128 lo[1u << kExhaustiveMax], hi[1u << kExhaustiveMax];
    double area[1u << kExhaustiveMax];
    lo[0] = _mm_set1_ps(INFINITY);
    hi[0] = _mm_set1_ps(-INFINITY);
    for (uint32_t m = 1; m <= full; ++m) {
        const uint32_t low = uint32_t(__builtin_ctz(m)), rest = m & (m - 1);
        lo[m] = _mm_min_ps(lo[rest], LoadLo(refs[low]));
        hi[m] = _mm_max_ps(hi[rest], LoadHi(refs[low]));
        area[m] = HalfArea(lo[m], hi[m]);
    }
    // Element 0 always on the left: each bipartition once.
    uint32_t best = 0;
    *bestCost = INFINITY;
    for (uint32_t m = 1; m < full; m += 2) {
        const uint32_t n = PopCount5(m);
        const double cost = area[m] * n + area[full ^ m] * (count - n);
        if (cost < *bestCost) { *bestCost = cost; best = m; }
    }
    if (best == 0) return false;
    PrimRef sorted[kExhaustiveMax];
    uint32_t nl = 0, nr = PopCount5(best);
    const uint32_t split = nr;
    for (uint32_t i = 0; i < count; ++i) sorted[(best >> i) & 1 ? nl++ : nr++] = refs[i];
    std::copy(sorted, sorted + count, refs);
    *left = WithCentroids(allRefs, r.begin, r.begin + split, lo[best], hi[best], r.depth + 1);
    *right = WithCentroids(allRefs, r.begin + split, r.end, lo[full ^ best], hi[full ^ best], r.depth + 1);
    return true;
}

// Full sweep: sort by centroid on each axis, evaluate every split position.
bool SweepSplit(PrimRef* allRefs, const Range& r, double* bestCost, Range* left, Range* right) {
    constexpr uint32_t kMax = kSweepMax;
    const uint32_t count = r.end - r.begin;
    PrimRef* const refs = allRefs + r.begin;
    alignas(16) float centroid[kMax][4];
    for (uint32_t i = 0; i < count; ++i) _mm_store_ps(centroid[i], Centroid(refs[i]));
    struct Entry { float key; uint32_t index; };
    Entry order[3][kMax];
    double rightArea[kMax];
    int bestAxis = -1;
    uint32_t bestSplit = 0;
    *bestCost = INFINITY;
    for (int a = 0; a < 3; ++a) {
        if (!(Lane(r.chi, a) > Lane(r.clo, a))) continue;
        Entry* o = order[a];
        for (uint32_t i = 0; i < count; ++i) {
            // Insertion sort; ties by position keep it deterministic.
            const Entry e{centroid[i][a], i};
            uint32_t k = i;
            while (k > 0 && o[k - 1].key > e.key) { o[k] = o[k - 1]; --k; }
            o[k] = e;
        }
        __m128 lo = _mm_set1_ps(INFINITY), hi = _mm_set1_ps(-INFINITY);
        for (uint32_t k = count - 1; k > 0; --k) {
            lo = _mm_min_ps(lo, LoadLo(refs[o[k].index]));
            hi = _mm_max_ps(hi, LoadHi(refs[o[k].index]));
            rightArea[k] = HalfArea(lo, hi);
        }
        lo = _mm_set1_ps(INFINITY); hi = _mm_set1_ps(-INFINITY);
        for (uint32_t k = 0; k + 1 < count; ++k) {
            lo = _mm_min_ps(lo, LoadLo(refs[o[k].index]));
            hi = _mm_max_ps(hi, LoadHi(refs[o[k].index]));
            const double cost = HalfArea(lo, hi) * (k + 1) + rightArea[k + 1] * (count - k - 1);
            if (cost < *bestCost) { *bestCost = cost; bestAxis = a; bestSplit = k + 1; }
        }
    }
    if (bestAxis < 0) return false;
    PrimRef sorted[kMax];
    for (uint32_t k = 0; k < count; ++k) sorted[k] = refs[order[bestAxis][k].index];
    Side l, rr;
    for (uint32_t k = 0; k < count; ++k) {
        refs[k] = sorted[k];
        (k < bestSplit ? l : rr).Add(sorted[k]);
    }
    *left = l.ToRange(r.begin, r.begin + bestSplit, r.depth + 1);
    *right = rr.ToRange(r.begin + bestSplit, r.end, r.depth + 1);
    return true;
}

}  // namespace

bool SmallNodeSplit(PrimRef* refs, const Range& r, double* cost, Range* left, Range* right) {
    return r.end - r.begin <= kExhaustiveMax ? BestSubsetSplit(refs, r, cost, left, right)
                                             : SweepSplit(refs, r, cost, left, right);
}

}  // namespace asval::builder::detail
