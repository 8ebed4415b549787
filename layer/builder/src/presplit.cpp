// Spatial pre-splitting of oversized triangle references (see bvh_triangles.h).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <vector>

#include "asval/builder/bvh_triangles.h"
#include "asval/builder/vertex_format.h"
#include "bvh_internal.h"
#include "format_traits.h"
#include "lbvh_hugepages.h"
#include "presplit_clip.h"
#include "presplit_parallel.h"
#include "float_mode.h"

namespace asval::builder {
namespace {

constexpr uint32_t kMaxPiecesPerTriangle = 128;
constexpr double kTrigger = 16.0;  // Auto splits only when the largest box exceeds 16x the mean box area

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

struct Candidate {
    double area;
    uint32_t index;
};

// References per chunk of the area scans, candidates per chunk of the splitting (fixed: the output must
// not depend on the thread count).
constexpr size_t kScanChunk = 1 << 16;
constexpr size_t kSplitChunk = 64;  // small: candidates come largest first, so early chunks hold most pieces

// Half surface area of a box, in double (HalfArea: e0*e1 + e1*e2 + e2*e0); 0 for a box with an infinite or
// NaN bound, which is never split.
inline double FiniteArea(const PrimRef& r) {
    const __m128 big = _mm_set1_ps(FLT_MAX);
    const __m128 absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF));
    const __m128 lo = detail::LoadLo(r), hi = detail::LoadHi(r);
    const int ok = _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(_mm_and_ps(lo, absMask), big),
                                              _mm_cmple_ps(_mm_and_ps(hi, absMask), big)));
    return (ok & 7) == 7 ? detail::HalfArea(lo, hi) : 0.0;
}

}  // namespace

uint32_t SplitLargeTriangles(const TriangleGeometryView* geometries, size_t geometryCount,
                             const BuildOptions& options, BuildInput* input) {
    const detail::FloatModeGuard mode;
    std::vector<PrimRef>& refs = input->refs;
    if (options.spatialSplits == SpatialSplits::Off || refs.empty()) return 0;
    // Pieces clip the time-0 triangle only: a moving triangle would leave its pieces at t > 0.
    for (size_t g = 0; g < geometryCount; ++g)
        if (geometries[g].motionVertexData) return 0;
    const uint32_t threads = std::max<uint32_t>(options.threads, 1);
    const size_t n = refs.size();
    // Every pass below works in fixed chunks whose results are combined in chunk order, so the output is
    // the same for any thread count (the area sum too: its rounding depends on the chunking only).
    const size_t scanChunks = (n + kScanChunk - 1) / kScanChunk;
    struct Scan {
        double sum = 0, largest = 0;
        std::vector<Candidate> candidates;
    };
    std::vector<Scan> scans(scanChunks);
    detail::ForEachChunk(threads, scanChunks, [&](size_t c) {
        Scan& s = scans[c];
        for (size_t i = c * kScanChunk, e = std::min(n, i + kScanChunk); i < e; ++i) {
            const double a = FiniteArea(refs[i]);
            s.sum += a;
            s.largest = std::max(s.largest, a);
        }
    });
    double sum = 0, largest = 0;
    for (const Scan& s : scans) { sum += s.sum; largest = std::max(largest, s.largest); }
    const double mean = sum / double(n);
    // "Needs splits": some reference is far larger than the average one. Measured max/mean: uniform 3.6,
    // sphere 1.5, terrain 2.0, clustered 380-455 (10k..1M). On meshes nothing below runs.
    if (options.spatialSplits == SpatialSplits::Auto && !(largest > kTrigger * mean)) return 0;
    const double threshold = double(options.splitFactor) * mean;
    const uint64_t budget = uint64_t(double(n) * std::max(0.0f, options.splitBudget));
    if (budget == 0) return 0;
    detail::ForEachChunk(threads, scanChunks, [&](size_t c) {
        Scan& s = scans[c];
        for (size_t i = c * kScanChunk, e = std::min(n, i + kScanChunk); i < e; ++i) {
            const double a = FiniteArea(refs[i]);  // 0 for an infinite box: never a candidate
            if (a > threshold) s.candidates.push_back({a, uint32_t(i)});
        }
    });
    std::vector<Candidate> byArea;
    {
        size_t total = 0;
        for (const Scan& s : scans) total += s.candidates.size();
        byArea.reserve(total);
        for (Scan& s : scans) {
            byArea.insert(byArea.end(), s.candidates.begin(), s.candidates.end());
            std::vector<Candidate>().swap(s.candidates);
        }
    }
    if (byArea.empty()) return 0;
    // Largest first; the budget is shared out in proportion to area. Areas are computed once (a
    // comparator computing them dominated this function).
    std::sort(byArea.begin(), byArea.end(), [](const Candidate& x, const Candidate& y) {
        return x.area > y.area || (x.area == y.area && x.index < y.index);
    });
    double candidateArea = 0;
    for (const Candidate& c : byArea) candidateArea += c.area;
    std::vector<uint32_t> caps(byArea.size());
    uint64_t capSum = 0;
    for (size_t c = 0; c < byArea.size(); ++c) {
        const double share = double(budget) * byArea[c].area / candidateArea;
        const uint64_t left = budget > capSum ? budget - capSum : 0;
        caps[c] = uint32_t(std::min<double>({double(kMaxPiecesPerTriangle), share + 1, double(left + 1)}));
        if (caps[c] >= 2) capSum += caps[c] - 1;
    }
    // Cut the candidates in chunks: each chunk replaces its references by their first pieces (distinct
    // elements of refs) and keeps the other pieces, in candidate order, for the append below.
    const TriangleFetcher fetch(geometries, geometryCount);
    const size_t splitChunks = (byArea.size() + kSplitChunk - 1) / kSplitChunk;
    std::vector<std::vector<PrimRef>> extra(splitChunks);
    detail::ForEachChunk(threads, splitChunks, [&](size_t chunk) {
        std::vector<PrimRef> pieces;
        std::vector<PrimRef>& more = extra[chunk];
        for (size_t c = chunk * kSplitChunk, e = std::min(byArea.size(), c + kSplitChunk); c < e; ++c) {
            if (caps[c] < 2) continue;
            PrimRef& ref = refs[byArea[c].index];
            double tri[3][3];
            fetch.Fetch(ref.id, tri);
            double magnitude = 0;
            for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::fabs(double(ref.lo[a])), std::fabs(double(ref.hi[a]))});
            pieces.clear();
            detail::PieceSplitter(tri, magnitude * 0x1p-40, threshold).Split(ref, caps[c], &pieces);
            ref = pieces[0];
            more.insert(more.end(), pieces.begin() + 1, pieces.end());
        }
    });
    std::vector<Candidate>().swap(byArea);
    size_t added = 0;
    for (const auto& m : extra) added += m.size();
    if (added == 0) return 0;
    // One exact-size array: no growth, no unused tail carried into the build's peak.
    std::vector<PrimRef> merged;
    detail::ReserveHuge(merged, n + added);
    merged.insert(merged.end(), refs.begin(), refs.end());
    std::vector<PrimRef>().swap(refs);
    for (auto& m : extra) {
        merged.insert(merged.end(), m.begin(), m.end());
        std::vector<PrimRef>().swap(m);
    }
    refs.swap(merged);
    return uint32_t(added);
}

Bvh BuildTriangleBvh(const TriangleGeometryView* geometries, size_t geometryCount, bool allowUpdate,
                     const BuildOptions& options, BuildInput* excludedCounts) {
    const detail::FloatModeGuard mode;
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
