// Conservative primitive boxes for the BVH (see build_input.h).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <emmintrin.h>
#include <vector>

#include "asval/builder/build_input.h"
#include "asval/builder/classify.h"
#include "asval/builder/vertex_format.h"
#include "conservative_bounds.h"
#include "format_traits.h"
#include "motion_instances.h"
#include "motion_triangles.h"
#include "float_mode.h"

namespace asval::builder {
namespace {

// The exact decoded value of a norm component is c / K, which the float decode rounds. Returns the float
// interval [lo, hi] that holds the exact value (equal bounds when the float is exact).
void NormInterval(float f, uint32_t k, int32_t code, float* lo, float* hi) {
    const double back = double(f) * double(k);  // exact: 24-bit times <= 16-bit
    *lo = *hi = f;
    if (back < double(code)) *hi = std::nextafter(f, INFINITY);
    else if (back > double(code)) *lo = std::nextafter(f, -INFINITY);
}

// Exact-value interval of each decoded component of one vertex.
void VertexInterval(const VertexFormatInfo& info, const uint8_t* p, float lo[3], float hi[3]) {
    float xyz[3];
    DecodeVertex(info, p, xyz);
    for (int c = 0; c < 3; ++c) lo[c] = hi[c] = xyz[c];
    if (info.kind != ComponentKind::Snorm && info.kind != ComponentKind::Unorm &&
        info.kind != ComponentKind::Unorm1010102)
        return;  // float formats decode exactly
    for (int c = 0; c < 3; ++c) {
        if (c >= info.componentCount && info.kind != ComponentKind::Unorm1010102) continue;  // Z = 0 exactly
        int32_t code;
        uint32_t k;
        if (info.kind == ComponentKind::Unorm1010102) {
            code = int32_t((detail::LoadU32(p) >> (10 * c)) & 0x3FFu);
            k = 1023;
        } else if (info.kind == ComponentKind::Unorm) {
            code = int32_t(info.componentBits == 8 ? p[c] : detail::LoadU16(p + 2 * c));
            k = (1u << info.componentBits) - 1;
        } else {
            code = info.componentBits == 8 ? int32_t(int8_t(p[c])) : int32_t(int16_t(detail::LoadU16(p + 2 * c)));
            k = (1u << (info.componentBits - 1)) - 1;
            if (code < -int32_t(k)) code = -int32_t(k);
        }
        NormInterval(xyz[c], k, code, &lo[c], &hi[c]);
    }
}

// Widens [lo, hi] by one vertex's exact interval, through the transform when there is one.
void AddVertex(const VertexFormatInfo& info, const uint8_t* p, const float* transform, float lo[3], float hi[3]) {
    float vlo[3], vhi[3];
    VertexInterval(info, p, vlo, vhi);
    if (transform) {
        float tlo[3], thi[3];
        detail::TransformBox(transform, vlo, vhi, tlo, thi);
        std::memcpy(vlo, tlo, sizeof vlo);
        std::memcpy(vhi, thi, sizeof vhi);
    }
    for (int c = 0; c < 3; ++c) {
        lo[c] = vlo[c] < lo[c] ? vlo[c] : lo[c];
        hi[c] = vhi[c] > hi[c] ? vhi[c] : hi[c];
    }
}

void Put(BuildInput* out, uint32_t id, const float lo[3], const float hi[3]) {
    PrimRef r;
    bool infinite = false;
    for (int c = 0; c < 3; ++c) {
        r.lo[c] = lo[c];
        r.hi[c] = hi[c];
        infinite |= !(std::fabs(lo[c]) <= FLT_MAX) || !(std::fabs(hi[c]) <= FLT_MAX);  // no NaN reaches here
    }
    r.id = id;
    r.aux = 0;
    out->infiniteBoxes += infinite;
    out->refs.push_back(r);
}

// Three floats into lanes 0..2 (lane 3 = 0) without reading past them.
inline __m128 Load3(const uint8_t* p) {
    double xy;  // memcpy: the data may be unaligned (any stride)
    float z;
    std::memcpy(&xy, p, 8);
    std::memcpy(&z, p + 8, 4);
    return _mm_movelh_ps(_mm_castpd_ps(_mm_set_sd(xy)), _mm_set_ss(z));
}

// Put() for boxes already in SIMD registers (the float fast path).
inline void PutSimd(BuildInput* out, uint32_t id, __m128 lo, __m128 hi) {
    alignas(16) PrimRef r;
    _mm_store_ps(r.lo, lo);
    _mm_store_ps(r.hi, hi);
    r.id = id;
    r.aux = 0;
    const __m128 absMask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF)), big = _mm_set1_ps(FLT_MAX);
    const int infinite = _mm_movemask_ps(_mm_or_ps(_mm_cmpnle_ps(_mm_and_ps(lo, absMask), big),
                                                   _mm_cmpnle_ps(_mm_and_ps(hi, absMask), big))) & 7;
    out->infiniteBoxes += infinite != 0;
    out->refs.push_back(r);
}

// Sorts a primitive's classification into "kept" or one of the exclusion counters.
bool Keep(uint8_t s, bool allowUpdate, BuildInput* out) {
    if (s & kStateUnreadable) { ++out->excludedUnreadable; return false; }
    if (!(s & kStateActive)) { ++out->excludedInactive; return false; }
    if (s & kStateUndefined) { ++out->excludedUndefined; return false; }
    if (s & kStateInvalidAabb) { ++out->excludedInvalid; return false; }
    if (s & kStateSameIndex) { ++out->excludedSameIndex; return false; }
    if ((s & kStateDegenerate) && !allowUpdate) { ++out->excludedDegenerate; return false; }
    return true;
}

// What both triangle paths need before computing boxes: each primitive's state, the format, the index
// size and the transform (when one is given and readable).
struct TriangleSetup {
    std::vector<uint8_t> states;
    const VertexFormatInfo* info = nullptr;
    int indexBytes = 0;
    bool transformed = false;
    float m[12] = {};

    // False (everything counted unreadable) when the geometry cannot be classified.
    bool Prepare(const TriangleGeometryView& view, BuildInput* out) {
        const uint32_t n = view.range.primitiveCount;
        states.resize(n);
        const ClassifyResult cr = ClassifyTriangles(view, nullptr, states.data());
        if (cr.status != ClassifyStatus::Ok) { out->excludedUnreadable += n; return false; }
        info = FindVertexFormat(view.vertexFormat);
        indexBytes = IndexTypeBytes(view.indexType);
        transformed = view.transformData && !cr.transformUnreadable;
        if (transformed)
            std::memcpy(m, static_cast<const uint8_t*>(view.transformData) + view.range.transformOffset, sizeof m);
        return true;
    }
};

// Motion triangles: the union of the conservative boxes of the triangle at time 0 and at time 1. A vertex
// at time t is (1 - t) v0 + t v1 and the (affine) transform keeps that a convex combination of the two
// transformed ends, so the triangle at every t lies in the hull of its six transformed vertices.
void AppendMotionTriangles(const TriangleGeometryView& view, bool allowUpdate, uint32_t idBase, BuildInput* out) {
    TriangleSetup set;
    if (!set.Prepare(view, out)) return;  // classified by the motion rules
    const uint32_t n = view.range.primitiveCount;
    const std::vector<uint8_t>& states = set.states;
    const VertexFormatInfo& info = *set.info;
    const int indexBytes = set.indexBytes;
    const bool transformed = set.transformed;
    const float* const m = set.m;
    const uint8_t* const buffers[2] = {static_cast<const uint8_t*>(view.vertexData),
                                       static_cast<const uint8_t*>(view.motionVertexData)};
    out->refs.reserve(out->refs.size() + n);
    for (uint32_t t = 0; t < n; ++t) {
        if (!Keep(states[t], allowUpdate, out)) continue;
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int k = 0; k < 3; ++k) {
            const uint64_t off = detail::MotionVertexOffset(view, indexBytes, t, k);  // readable at both times
            for (const uint8_t* vb : buffers) AddVertex(info, vb + off, transformed ? m : nullptr, lo, hi);
        }
        Put(out, idBase + t, lo, hi);
    }
}

}  // namespace

void AppendTriangles(const TriangleGeometryView& view, bool allowUpdate, uint32_t idBase, BuildInput* out) {
    const detail::FloatModeGuard mode;
    if (view.motionVertexData) { AppendMotionTriangles(view, allowUpdate, idBase, out); return; }
    TriangleSetup set;
    if (!set.Prepare(view, out)) return;
    const uint32_t n = view.range.primitiveCount;
    const std::vector<uint8_t>& states = set.states;
    const VertexFormatInfo& info = *set.info;
    const int indexBytes = set.indexBytes;
    const bool transformed = set.transformed;
    const float* const m = set.m;
    const auto* vb = static_cast<const uint8_t*>(view.vertexData);
    // Only dereferenced for readable (kept) primitives; never offset a null pointer.
    const auto* ib = indexBytes && view.indexData ? static_cast<const uint8_t*>(view.indexData) + view.range.primitiveOffset : nullptr;
    const uint64_t nonIndexedBase = uint64_t(view.range.primitiveOffset) + view.vertexStride * view.range.firstVertex;
    out->refs.reserve(out->refs.size() + n);
    if (info.kind == ComponentKind::Float32 && info.componentCount >= 3 && !transformed) {
        // Fast path (the common case): float vertices are exact, the box is their min / max.
        for (uint32_t t = 0; t < n; ++t) {
            if (!Keep(states[t], allowUpdate, out)) continue;
            __m128 v[3];
            for (int k = 0; k < 3; ++k) {
                uint64_t off;
                if (indexBytes == 0) {
                    off = nonIndexedBase + (3ull * t + uint64_t(k)) * view.vertexStride;
                } else {
                    const uint8_t* ip = ib + (3ull * t + uint64_t(k)) * uint64_t(indexBytes);
                    const uint64_t idx = indexBytes == 1 ? ip[0] : indexBytes == 2 ? detail::LoadU16(ip) : detail::LoadU32(ip);
                    off = (idx + view.range.firstVertex) * view.vertexStride;
                }
                v[k] = Load3(vb + off);
            }
            // min(v0, min(v1, v2)) with std::min's operand order (it decides which zero a +-0 tie keeps).
            const __m128 lo = _mm_min_ps(_mm_min_ps(v[2], v[1]), v[0]);
            const __m128 hi = _mm_max_ps(_mm_max_ps(v[2], v[1]), v[0]);
            PutSimd(out, idBase + t, lo, hi);
        }
        return;
    }
    for (uint32_t t = 0; t < n; ++t) {
        if (!Keep(states[t], allowUpdate, out)) continue;
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int k = 0; k < 3; ++k) {
            uint64_t off;
            if (indexBytes == 0) {
                off = nonIndexedBase + (3ull * t + uint64_t(k)) * view.vertexStride;
            } else {
                const uint8_t* ip = ib + (3ull * t + uint64_t(k)) * uint64_t(indexBytes);
                const uint64_t idx = indexBytes == 1 ? ip[0] : indexBytes == 2 ? detail::LoadU16(ip) : detail::LoadU32(ip);
                off = (idx + view.range.firstVertex) * view.vertexStride;  // readable: the classifier checked
            }
            AddVertex(info, vb + off, transformed ? m : nullptr, lo, hi);
        }
        Put(out, idBase + t, lo, hi);
    }
}

void AppendAabbs(const AabbGeometryView& view, bool allowUpdate, uint32_t idBase, BuildInput* out) {
    const detail::FloatModeGuard mode;
    const uint32_t n = view.range.primitiveCount;
    std::vector<uint8_t> states(n);
    ClassifyAabbs(view, nullptr, states.data());
    out->refs.reserve(out->refs.size() + n);
    // Degenerate AABBs (points) "may invoke the intersection shader": kept regardless of allowUpdate.
    (void)allowUpdate;
    for (uint32_t i = 0; i < n; ++i) {
        if (!Keep(uint8_t(states[i] & ~kStateDegenerate), true, out)) continue;
        const uint8_t* p = static_cast<const uint8_t*>(view.data) + view.range.primitiveOffset + uint64_t(i) * view.stride;
        float b[6];
        std::memcpy(b, p, sizeof b);
        Put(out, idBase + i, b, b + 3);
    }
}

namespace {

// Motion instances: the record's own reference field; boxes conservative over every time in [0, 1]
// (motion_instances.cpp). Exclusions as for static instances.
void AppendMotionInstances(const InstanceGeometryView& view, BlasLookup lookup, void* user, uint32_t idBase,
                           BuildInput* out) {
    const uint32_t n = view.range.primitiveCount;
    std::vector<uint8_t> states(n);
    ClassifyInstances(view, nullptr, states.data());
    out->refs.reserve(out->refs.size() + n);
    for (uint32_t i = 0; i < n; ++i) {
        if (!Keep(states[i], true, out)) continue;
        const detail::MotionRecord rec = detail::LocateMotionInstance(view, i);  // Ok: the classifier read it
        const BlasSummary blas = lookup ? lookup(detail::MotionReference(rec), user) : BlasSummary{};
        if (!blas.known) { ++out->excludedInvalid; continue; }
        const bool degenerate = blas.activePrimitives == 0;
        float lo[3], hi[3];
        detail::MotionInstanceBox(rec, blas.lo, blas.hi, degenerate, lo, hi);
        out->degenerateInstances += degenerate;
        Put(out, idBase + i, lo, hi);
    }
}

}  // namespace

void AppendInstances(const InstanceGeometryView& view, BlasLookup lookup, void* user, uint32_t idBase,
                     BuildInput* out) {
    const detail::FloatModeGuard mode;
    if (view.motionInstances) { AppendMotionInstances(view, lookup, user, idBase, out); return; }
    const uint32_t n = view.range.primitiveCount;
    std::vector<uint8_t> states(n);
    ClassifyInstances(view, nullptr, states.data());
    out->refs.reserve(out->refs.size() + n);
    const uint64_t elem = view.arrayOfPointers ? sizeof(const void*) : 64;
    for (uint32_t i = 0; i < n; ++i) {
        if (!Keep(states[i], true, out)) continue;
        const uint8_t* inst = static_cast<const uint8_t*>(view.data) + view.range.primitiveOffset + uint64_t(i) * elem;
        if (view.arrayOfPointers) {
            const void* ptr;
            std::memcpy(&ptr, inst, sizeof ptr);
            inst = static_cast<const uint8_t*>(ptr);
        }
        float m[12];
        uint64_t reference;
        std::memcpy(m, inst, sizeof m);
        std::memcpy(&reference, inst + 56, 8);
        const BlasSummary blas = lookup ? lookup(reference, user) : BlasSummary{};
        if (!blas.known) { ++out->excludedInvalid; continue; }
        float lo[3], hi[3];
        if (blas.activePrimitives == 0) {
            // Degenerate instance: "a point at the instance origin, specified by transform".
            for (int r = 0; r < 3; ++r) {
                const float t = m[4 * r + 3];
                lo[r] = std::isnan(t) ? -INFINITY : t;
                hi[r] = std::isnan(t) ? INFINITY : t;
            }
            ++out->degenerateInstances;
        } else {
            detail::TransformBox(m, blas.lo, blas.hi, lo, hi);
        }
        Put(out, idBase + i, lo, hi);
    }
}

}  // namespace asval::builder
