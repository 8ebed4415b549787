// Motion triangles: both times are classified by the ordinary (fast) pass, then combined per triangle.
// The spec defines activity on "any vertex"; a motion triangle has six (three per time), so (decision):
//  * inactive   iff an X at time 0 or at time 1 is NaN (its position at every t > 0 or t < 1 would be NaN);
//  * undefined  iff not inactive and a Y or Z at either time is NaN;
//  * degenerate iff it is degenerate at every t in [0, 1]. The spec's condition is a disjunction of six
//    clauses (vertex pair 01, 12 or 02 identical; all three share X&Y, X&Z or Y&Z), each a conjunction of
//    equalities of two interpolated components. Such an equality, (1 - t) d0 + t d1 = 0, holds at every t
//    iff it holds at t = 0 and t = 1, and otherwise at one t at most. If the disjunction held at every t,
//    one clause would hold at infinitely many t, so each of its equalities at every t: hence "degenerate at
//    every t" iff one clause holds at both ends. (A triangle degenerate at both ends through different
//    clauses is non-degenerate in between and must not be discarded.)
//  * unreadable iff either time's vertices (or the indices) are not provided; recorded active.
// The index hash, maxVertex violations and the transform checks come from the time-0 pass (the indices and
// the transform are shared).
#include "motion_triangles.h"

#include <vector>

#include "asval/builder/vertex_format.h"
#include "format_traits.h"

namespace asval::builder::detail {
namespace {

// The six clauses of the degenerate definition that hold, as bits; IEEE == on decoded values (value
// equality: +0 == -0, the two SNORM codes of -1 decode equal; NaN equals nothing).
unsigned DegenerateClauses(const VertexFormatInfo& info, const uint8_t* p0, const uint8_t* p1, const uint8_t* p2) {
    float a[3], b[3], c[3];
    DecodeVertex(info, p0, a);
    DecodeVertex(info, p1, b);
    DecodeVertex(info, p2, c);
    bool e01[3], e12[3], e02[3], all[3];
    for (int i = 0; i < 3; ++i) {
        e01[i] = a[i] == b[i];
        e12[i] = b[i] == c[i];
        e02[i] = a[i] == c[i];
        all[i] = e01[i] && e12[i];
    }
    return unsigned(e01[0] && e01[1] && e01[2]) | unsigned(e12[0] && e12[1] && e12[2]) << 1 |
           unsigned(e02[0] && e02[1] && e02[2]) << 2 | unsigned(all[0] && all[1]) << 3 |
           unsigned(all[0] && all[2]) << 4 | unsigned(all[1] && all[2]) << 5;
}

}  // namespace

uint64_t MotionVertexOffset(const TriangleGeometryView& view, int indexBytes, uint32_t t, int k) {
    if (indexBytes == 0)
        return uint64_t(view.range.primitiveOffset) +
               view.vertexStride * (uint64_t(view.range.firstVertex) + 3ull * t + uint64_t(k));
    const uint8_t* ip = static_cast<const uint8_t*>(view.indexData) + view.range.primitiveOffset +
                        (3ull * t + uint64_t(k)) * uint64_t(indexBytes);
    const uint64_t idx = indexBytes == 1 ? ip[0] : indexBytes == 2 ? LoadU16(ip) : LoadU32(ip);
    return (idx + view.range.firstVertex) * view.vertexStride;
}

ClassifyResult ClassifyMotionTriangles(const TriangleGeometryView& view, ActivityRecord* record, uint8_t* states) {
    TriangleGeometryView at0 = view;
    at0.motionVertexData = nullptr;
    at0.motionVertexDataBytes = 0;
    TriangleGeometryView at1 = at0;
    at1.vertexData = view.motionVertexData;
    at1.vertexDataBytes = view.motionVertexDataBytes;
    const uint32_t n = view.range.primitiveCount;
    std::vector<uint8_t> s0(n), s1(n);
    ClassifyResult r = ClassifyTriangles(at0, record, s0.data());  // record: index hash (bits redone below)
    if (r.status != ClassifyStatus::Ok) return r;
    ClassifyTriangles(at1, nullptr, s1.data());
    const VertexFormatInfo& info = *FindVertexFormat(view.vertexFormat);
    const int indexBytes = IndexTypeBytes(view.indexType);
    const auto* vb0 = static_cast<const uint8_t*>(view.vertexData);
    const auto* vb1 = static_cast<const uint8_t*>(view.motionVertexData);
    r.active = r.degenerate = r.sameIndex = r.undefinedNaN = r.unreadable = 0;
    r.firstUndefined = r.firstUnreadable = UINT32_MAX;
    uint64_t word = 0;
    for (uint32_t t = 0; t < n; ++t) {
        const uint8_t a = s0[t], b = s1[t];
        uint8_t state;
        if ((a | b) & kStateUnreadable) {
            state = kStateActive | kStateUnreadable;
            ++r.unreadable;
            if (r.firstUnreadable == UINT32_MAX) r.firstUnreadable = t;
        } else if (!(a & b & kStateActive)) {
            state = 0;
        } else {
            state = uint8_t(kStateActive | ((a | b) & kStateUndefined) | (a & kStateSameIndex));
            if (a & b & kStateDegenerate) {  // necessary; the clause test decides
                unsigned both = ~0u;
                for (const uint8_t* vb : {vb0, vb1})
                    both &= DegenerateClauses(info, vb + MotionVertexOffset(view, indexBytes, t, 0),
                                              vb + MotionVertexOffset(view, indexBytes, t, 1),
                                              vb + MotionVertexOffset(view, indexBytes, t, 2));
                if (both) state |= kStateDegenerate;
            }
            if (state & kStateUndefined) {
                ++r.undefinedNaN;
                if (r.firstUndefined == UINT32_MAX) r.firstUndefined = t;
            }
            r.degenerate += (state & kStateDegenerate) != 0;
            r.sameIndex += (state & kStateSameIndex) != 0;
        }
        const uint64_t bit = state & kStateActive;
        r.active += uint32_t(bit);
        word |= bit << (t & 63);
        if ((t & 63) == 63) {
            if (record) record->activeBits[t >> 6] = word;
            word = 0;
        }
        if (states) states[t] = state;
    }
    if (record && (n & 63) != 0) record->activeBits[n >> 6] = word;
    r.inactive = n - r.active;
    if (record) record->activeCount = r.active;
    return r;
}

}  // namespace asval::builder::detail
