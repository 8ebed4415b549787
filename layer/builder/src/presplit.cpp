// Spatial pre-splitting of oversized triangle references (see bvh_triangles.h).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "asval/builder/bvh_triangles.h"
#include "asval/builder/vertex_format.h"
#include "conservative_bounds.h"
#include "format_traits.h"

namespace asval::builder {
namespace {

constexpr uint32_t kMaxPiecesPerTriangle = 128;
constexpr double kTrigger = 16.0;  // Auto splits only when the largest box exceeds 16x the mean box area

double Area(const float lo[3], const float hi[3]) {
    double e[3];
    for (int a = 0; a < 3; ++a) e[a] = std::max(0.0, double(hi[a]) - double(lo[a]));
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

bool Finite(const PrimRef& r) {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(r.lo[a]) || !std::isfinite(r.hi[a])) return false;
    return true;
}

// Triangle vertices in the BVH's frame, in double: exact for untransformed float formats, within 2^-50
// (relative) otherwise, which the clipping margin covers.
class TriangleFetcher {
public:
    TriangleFetcher(const TriangleGeometryView* g, size_t n) : geoms_(g, g + n) {
        uint32_t base = 0;
        for (const auto& v : geoms_) { bases_.push_back(base); base += v.range.primitiveCount; }
    }
    void Fetch(uint32_t id, double out[3][3]) const {
        const size_t gi = size_t(std::upper_bound(bases_.begin(), bases_.end(), id) - bases_.begin()) - 1;
        const TriangleGeometryView& v = geoms_[gi];
        const uint32_t t = id - bases_[gi];
        const VertexFormatInfo& info = *FindVertexFormat(v.vertexFormat);
        const int ib = IndexTypeBytes(v.indexType);
        float m[12];
        // As AppendTriangles: a transform whose 48 bytes were not provided is not applied.
        const bool xf = v.transformData != nullptr && v.range.transformOffset <= v.transformDataBytes &&
                        v.transformDataBytes - v.range.transformOffset >= 48;
        if (xf) std::memcpy(m, static_cast<const uint8_t*>(v.transformData) + v.range.transformOffset, sizeof m);
        for (int k = 0; k < 3; ++k) {
            uint64_t off;
            if (ib == 0) {
                off = uint64_t(v.range.primitiveOffset) + v.vertexStride * (uint64_t(v.range.firstVertex) + 3ull * t + uint64_t(k));
            } else {
                const uint8_t* ip = static_cast<const uint8_t*>(v.indexData) + v.range.primitiveOffset + (3ull * t + uint64_t(k)) * uint64_t(ib);
                const uint64_t idx = ib == 1 ? ip[0] : ib == 2 ? detail::LoadU16(ip) : detail::LoadU32(ip);
                off = (idx + v.range.firstVertex) * v.vertexStride;
            }
            float p[3];
            DecodeVertex(info, static_cast<const uint8_t*>(v.vertexData) + off, p);
            for (int a = 0; a < 3; ++a) {
                out[k][a] = xf ? double(m[4 * a]) * p[0] + double(m[4 * a + 1]) * p[1] + double(m[4 * a + 2]) * p[2] + double(m[4 * a + 3])
                               : double(p[a]);
            }
        }
    }

private:
    std::vector<TriangleGeometryView> geoms_;
    std::vector<uint32_t> bases_;
};

struct Poly {
    double v[9][3];  // a triangle clipped by up to 6 planes has at most 9 vertices
    int n = 0;
};

// Keeps the part of `in` with sign * (x[axis] - c) <= 0.
void ClipPlane(const Poly& in, int axis, double c, double sign, Poly* out) {
    out->n = 0;
    for (int i = 0; i < in.n; ++i) {
        const double* a = in.v[i];
        const double* b = in.v[i + 1 == in.n ? 0 : i + 1];  // not `% n`: a division per edge showed in profiles
        const double da = sign * (a[axis] - c), db = sign * (b[axis] - c);
        if (da <= 0 && out->n < 9) std::memcpy(out->v[out->n++], a, sizeof(double) * 3);
        if (((da < 0 && db > 0) || (da > 0 && db < 0)) && out->n < 9) {
            const double t = da / (da - db);
            double* p = out->v[out->n++];
            for (int k = 0; k < 3; ++k) p[k] = a[k] + t * (b[k] - a[k]);
            p[axis] = c;
        }
    }
}

class Splitter {
public:
    Splitter(const double tri[3][3], double margin, double threshold, std::vector<PrimRef>* out)
        : margin_(margin), threshold_(threshold), out_(out) {
        std::memcpy(tri_, tri, sizeof tri_);
    }

    // Emits pieces of `box` (a conservative box of the triangle part inside it); `cap` pieces at most.
    void Split(const PrimRef& box, uint32_t cap) {
        if (cap <= 1 || Area(box.lo, box.hi) <= threshold_) { out_->push_back(box); return; }
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (double(box.hi[a]) - box.lo[a] > double(box.hi[axis]) - box.lo[axis]) axis = a;
        const float mid = float(0.5 * (double(box.lo[axis]) + double(box.hi[axis])));
        if (!(mid > box.lo[axis] && mid < box.hi[axis])) { out_->push_back(box); return; }
        PrimRef halves[2] = {box, box};
        halves[0].hi[axis] = mid;
        halves[1].lo[axis] = mid;
        PrimRef kept[2];
        int n = 0;
        for (const PrimRef& h : halves)
            if (Clip(h, &kept[n])) ++n;
        if (n == 0) { out_->push_back(box); return; }  // cannot happen for a non-empty part; stay safe
        if (n == 1) { Split(kept[0], cap); return; }
        Split(kept[0], cap / 2);
        Split(kept[1], cap - cap / 2);
    }

private:
    // Bounds of the triangle inside `cell` widened by the margin, widened again, rounded outward and
    // intersected with `cell`. False when nothing of the triangle is inside.
    bool Clip(const PrimRef& cell, PrimRef* out) const {
        Poly a, b;
        a.n = 3;
        std::memcpy(a.v, tri_, sizeof tri_);
        for (int axis = 0; axis < 3; ++axis) {
            ClipPlane(a, axis, double(cell.hi[axis]) + margin_, 1.0, &b);
            ClipPlane(b, axis, double(cell.lo[axis]) - margin_, -1.0, &a);
            if (a.n == 0) return false;
        }
        *out = cell;
        for (int axis = 0; axis < 3; ++axis) {
            double lo = INFINITY, hi = -INFINITY;
            for (int i = 0; i < a.n; ++i) { lo = std::min(lo, a.v[i][axis]); hi = std::max(hi, a.v[i][axis]); }
            out->lo[axis] = std::max(cell.lo[axis], detail::RoundDown(lo - margin_));
            out->hi[axis] = std::min(cell.hi[axis], detail::RoundUp(hi + margin_));
            if (out->lo[axis] > out->hi[axis]) return false;
        }
        return true;
    }

    double tri_[3][3];
    double margin_;
    double threshold_;
    std::vector<PrimRef>* out_;
};

}  // namespace

uint32_t SplitLargeTriangles(const TriangleGeometryView* geometries, size_t geometryCount,
                             const BuildOptions& options, BuildInput* input) {
    std::vector<PrimRef>& refs = input->refs;
    if (options.spatialSplits == SpatialSplits::Off || refs.empty()) return 0;
    double sum = 0, largest = 0;
    for (const PrimRef& r : refs) {
        const double a = Finite(r) ? Area(r.lo, r.hi) : 0.0;
        sum += a;
        largest = std::max(largest, a);
    }
    const double mean = sum / double(refs.size());
    // "Needs splits": some reference is far larger than the average one. Measured max/mean: uniform 3.6,
    // sphere 1.5, terrain 2.0, clustered 380-455 (10k..1M). On meshes nothing below runs.
    if (options.spatialSplits == SpatialSplits::Auto && !(largest > kTrigger * mean)) return 0;
    const double threshold = double(options.splitFactor) * mean;
    struct Candidate {
        double area;
        uint32_t index;
    };
    std::vector<Candidate> byArea;
    for (uint32_t i = 0; i < refs.size(); ++i) {
        if (!Finite(refs[i])) continue;
        const double a = Area(refs[i].lo, refs[i].hi);
        if (a > threshold) byArea.push_back({a, i});
    }
    if (byArea.empty()) return 0;
    const uint64_t budget = uint64_t(double(refs.size()) * std::max(0.0f, options.splitBudget));
    if (budget == 0) return 0;
    // Largest first; the budget is shared out in proportion to area. Areas are computed once (a
    // comparator computing them dominated this function).
    std::sort(byArea.begin(), byArea.end(), [](const Candidate& x, const Candidate& y) {
        return x.area > y.area || (x.area == y.area && x.index < y.index);
    });
    std::vector<uint32_t> candidates(byArea.size());
    double candidateArea = 0;
    for (size_t c = 0; c < byArea.size(); ++c) {
        candidates[c] = byArea[c].index;
        candidateArea += byArea[c].area;
    }
    // Piece caps first, so the reference array grows once (no doubling on push_back).
    std::vector<uint32_t> caps(candidates.size());
    uint64_t capSum = 0;
    for (size_t c = 0; c < candidates.size(); ++c) {
        const double share = double(budget) * byArea[c].area / candidateArea;
        const uint64_t left = budget > capSum ? budget - capSum : 0;
        caps[c] = uint32_t(std::min<double>({double(kMaxPiecesPerTriangle), share + 1, double(left + 1)}));
        if (caps[c] >= 2) capSum += caps[c] - 1;
    }
    std::vector<Candidate>().swap(byArea);
    refs.reserve(refs.size() + capSum);
    const TriangleFetcher fetch(geometries, geometryCount);
    std::vector<PrimRef> pieces;
    uint64_t added = 0;
    for (size_t c = 0; c < candidates.size(); ++c) {
        const uint32_t i = candidates[c];
        const PrimRef original = refs[i];
        const uint32_t cap = caps[c];
        if (cap < 2) continue;
        double tri[3][3];
        fetch.Fetch(original.id, tri);
        double magnitude = 0;
        for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::fabs(double(original.lo[a])), std::fabs(double(original.hi[a]))});
        pieces.clear();
        Splitter(tri, magnitude * 0x1p-40, threshold, &pieces).Split(original, cap);
        refs[i] = pieces[0];
        for (size_t k = 1; k < pieces.size(); ++k) refs.push_back(pieces[k]);
        added += pieces.size() - 1;
    }
    // The caps are upper bounds (clustered: 1.40x reserved for 1.16x used): return the unused tail so the
    // build's peak (references + tree) does not carry it. The copy's own peak is below the build's.
    if (refs.capacity() - refs.size() > refs.size() / 32) refs.shrink_to_fit();
    return uint32_t(added);
}

Bvh BuildTriangleBvh(const TriangleGeometryView* geometries, size_t geometryCount, bool allowUpdate,
                     const BuildOptions& options, BuildInput* excludedCounts) {
    BuildInput in;
    uint32_t base = 0;
    for (size_t g = 0; g < geometryCount; ++g) {
        AppendTriangles(geometries[g], allowUpdate, base, &in);
        base += geometries[g].range.primitiveCount;
    }
    const uint32_t added = SplitLargeTriangles(geometries, geometryCount, options, &in);
    if (excludedCounts) {  // the counters only: never a copy of the references
        std::vector<PrimRef> refs = std::move(in.refs);
        in.refs.clear();
        *excludedCounts = in;
        in.refs = std::move(refs);
    }
    Bvh bvh = BuildBvh(std::move(in), options);
    bvh.stats.splitReferences = added;
    bvh.stats.usedSpatialSplits = added > 0;
    return bvh;
}

}  // namespace asval::builder
