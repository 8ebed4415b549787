// Private: cutting one triangle's reference into pieces at spatial midpoints (the pre-splitter's inner
// loop, see bvh_triangles.h and presplit.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "asval/builder/build_input.h"

namespace asval::builder::detail {

// A convex polygon in double: the triangle clipped by the split planes above the current piece. Each
// axis-aligned clip adds at most one vertex to a convex polygon and the triangle inside a box has at most
// 9; the slack covers rounding-made near-duplicates, and overflowing it stops the split (never a vertex
// dropped).
struct Poly {
    static constexpr int kMax = 16;
    double v[kMax][3];
    int n = 0;
};

class PieceSplitter {
public:
    // tri: the triangle in the BVH's frame (within 2^-50 relative of exact, see presplit.cpp); margin:
    // 2^-40 x the largest coordinate of the original box; pieces of area <= threshold are not cut.
    PieceSplitter(const double tri[3][3], double margin, double threshold);

    // Appends to `out` pieces of `box` (the triangle's original reference) that together cover every point
    // of the exact triangle inside it; `cap` pieces at most.
    void Split(const PrimRef& box, uint32_t cap, std::vector<PrimRef>* out) const;

private:
    void SplitPiece(const Poly& poly, const PrimRef& box, uint32_t cap, uint32_t depth, std::vector<PrimRef>* out) const;
    // Piece of `cell` that bounds `poly` (+ margin, rounded outward, intersected with cell); false if empty.
    bool Bound(const Poly& poly, const PrimRef& cell, PrimRef* piece) const;

    Poly tri_;
    double margin_;
    double threshold_;
};

}  // namespace asval::builder::detail
