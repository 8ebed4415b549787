// Private: the exact SAH split of a small node (the binned SAH builder's nodes of at most kSweepMax
// references), without bins.
#pragma once

#include <cstdint>

#include "bvh_code.h"

namespace asval::builder::detail {

constexpr uint32_t kSweepMax = 12;      // nodes this small get an exact split instead of bins
constexpr uint32_t kExhaustiveMax = 5;  // nodes this small try every bipartition

// Best SAH split of refs[r.begin, r.end) (2 <= count <= kSweepMax): every bipartition for count <=
// kExhaustiveMax, else a full sweep of the centroid order on each axis. Reorders the references so the
// left child comes first, fills both children's ranges (exact boxes and centroid boxes, depth + 1) and
// the split's cost (left area * count + right area * count). False when no split exists (identical
// centroids on every axis, sweep only).
bool SmallNodeSplit(PrimRef* refs, const Range& r, double* cost, Range* left, Range* right);

}  // namespace asval::builder::detail
