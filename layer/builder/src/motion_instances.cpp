// VK_NV_ray_tracing_motion_blur instances: record layout, activity field, conservative motion boxes.
// Compiled with -ffp-contract=off like every builder file: the bounds below count each rounding.
#include "motion_instances.h"

#include <cmath>
#include <cstddef>
#include <cstring>

#include "asval/builder/build_input.h"
#include "conservative_bounds.h"
#include "format_traits.h"

namespace asval::builder::detail {
namespace {

// Layouts, checked against the installed headers' structures.
constexpr uint64_t kStaticBytes = 64, kMatrixBytes = 112, kSrtBytes = 144;
constexpr uint64_t kStaticRefAt = 56, kMatrixRefAt = 104, kSrtRefAt = 136;
constexpr uint64_t kBodyAt = 8;  // VkAccelerationStructureMotionInstanceNV::data
static_assert(sizeof(VkAccelerationStructureInstanceKHR) == kStaticBytes, "layout");
static_assert(sizeof(VkAccelerationStructureMatrixMotionInstanceNV) == kMatrixBytes, "layout");
static_assert(sizeof(VkAccelerationStructureSRTMotionInstanceNV) == kSrtBytes, "layout");
static_assert(offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference) == kStaticRefAt, "layout");
static_assert(offsetof(VkAccelerationStructureMatrixMotionInstanceNV, accelerationStructureReference) == kMatrixRefAt, "layout");
static_assert(offsetof(VkAccelerationStructureSRTMotionInstanceNV, accelerationStructureReference) == kSrtRefAt, "layout");
static_assert(offsetof(VkAccelerationStructureMotionInstanceNV, data) == kBodyAt, "layout");
static_assert(sizeof(VkAccelerationStructureMotionInstanceNV) == kMotionInstanceBytes, "layout");
static_assert(sizeof(VkSRTDataNV) == 64, "layout");

uint64_t ReferenceAt(MotionKind k) {
    return k == MotionKind::Static ? kStaticRefAt : k == MotionKind::Matrix ? kMatrixRefAt : kSrtRefAt;
}

// One correctly rounded operation's result r: the exact value lies in [Down(r), Up(r)] (IEEE 754 rounds to
// nearest, so the error is at most half an ulp; also true for subnormal results, sqrt and overflow to inf).
inline double Up(double r) { return std::nextafter(r, INFINITY); }
inline double Down(double r) { return std::nextafter(r, -INFINITY); }

// Hull of two float boxes.
void Hull(const float aLo[3], const float aHi[3], const float bLo[3], const float bHi[3], float lo[3], float hi[3]) {
    for (int c = 0; c < 3; ++c) {
        lo[c] = aLo[c] < bLo[c] ? aLo[c] : bLo[c];
        hi[c] = aHi[c] > bHi[c] ? aHi[c] : bHi[c];
    }
}

// A point per axis, NaN meaning "anywhere".
void PointBox(const float p[3], float lo[3], float hi[3]) {
    for (int c = 0; c < 3; ++c) {
        lo[c] = std::isnan(p[c]) ? -INFINITY : p[c];
        hi[c] = std::isnan(p[c]) ? INFINITY : p[c];
    }
}

// Matrix motion: M(t) = M0 (1 - t) + M1 t entry-wise, so for a fixed point x, M(t) x = (1 - t) M0 x + t M1 x
// lies on the segment [M0 x, M1 x]. Both ends lie in the hull H of the conservative boxes of M0(box) and
// M1(box), H is convex, so every M(t) x, for every x in the BLAS box and t in [0, 1], lies in H.
void MatrixBox(const uint8_t* body, const float bLo[3], const float bHi[3], bool degenerate, float lo[3], float hi[3]) {
    float m0[12], m1[12];
    std::memcpy(m0, body, sizeof m0);
    std::memcpy(m1, body + 48, sizeof m1);
    float lo0[3], hi0[3], lo1[3], hi1[3];
    if (degenerate) {  // the instance origin M(t) 0 = the translation column, on the segment of the two
        const float t0[3] = {m0[3], m0[7], m0[11]}, t1[3] = {m1[3], m1[7], m1[11]};
        PointBox(t0, lo0, hi0);
        PointBox(t1, lo1, hi1);
    } else {
        detail::TransformBox(m0, bLo, bHi, lo0, hi0);
        detail::TransformBox(m1, bLo, bHi, lo1, hi1);
    }
    Hull(lo0, hi0, lo1, hi1, lo, hi);
}

// Upper bound of the sum of squares of three doubles whose squares are exact (floats squared fit in a
// double: 48 significant bits, no overflow or underflow). NaN stays NaN.
double SumSquaresUp(float a, float b, float c) {
    return Up(Up(double(a) * a + double(b) * b) + double(c) * c);
}

// SRT motion. Per the spec each of the 16 SRT values interpolates linearly (S's 9 values, the quaternion
// component-wise, T), and the transform at time t is T(t) x R(q(t)) x S(t). The quaternion q(t) is in general
// not of unit length and the spec does not say whether R normalises it, so the box covers both readings:
//   (a) R = the rotation of q / |q| (orthogonal: |R y| = |y|);
//   (b) R = the unit-quaternion formula applied to q as is: R = (1 - 2|v|^2) I + 2 v v^T + 2 w [v]x
//       (q = (v, w)). It maps v to v and a u orthogonal to v to (1 - 2|v|^2) u + 2w (v x u), two orthogonal
//       parts, so |R y| <= g |y| with g^2 = max(1, (1 - 2|v|^2)^2 + 4 w^2 |v|^2) = max(1, 1 + 4|v|^2 (|q|^2 - 1))
//       <= max(1, (2|q|^2 - 1)^2) (as |v|^2 <= |q|^2): g <= G = max(1, 2|q|^2 - 1).
// |q(t)| <= max(|q0|, |q1|) (a norm is convex), so G = max(1, 2 max(|q0|^2, |q1|^2) - 1) bounds both readings
// at every t. S(t) x = (1 - t) S0 x + t S1 x (S's entries interpolate, x fixed) lies in the hull U of the
// conservative boxes of S0(box) and S1(box), so |S(t) x| <= rho = max over U of |y| = sqrt(sum over axes of
// max(lo^2, hi^2)). Hence |R(t) S(t) x| <= G rho on every axis, and with T(t) on the segment [T0, T1] each
// axis of the image lies in [min(T0, T1) - G rho, max(T0, T1) + G rho]. Every operation below is rounded
// outward (Up / Down after each one, RoundDown / RoundUp to float at the end); a NaN input makes the
// affected bounds infinite (NaN in S or q: every axis; NaN in T: that axis).
void SrtBox(const uint8_t* body, const float bLo[3], const float bHi[3], bool degenerate, float lo[3], float hi[3]) {
    float srt[2][16];
    std::memcpy(srt[0], body, 64);
    std::memcpy(srt[1], body + 64, 64);
    const float zero[3] = {0, 0, 0};
    const float* boxLo = degenerate ? zero : bLo;  // degenerate: the instance origin, the point 0
    const float* boxHi = degenerate ? zero : bHi;
    float uLo[3], uHi[3];
    double n2 = 0;
    for (int e = 0; e < 2; ++e) {
        const float* d = srt[e];  // sx a b pvx sy c pvy sz pvz qx qy qz qw tx ty tz
        const float s[12] = {d[0], d[1], d[2], d[3], 0, d[4], d[5], d[6], 0, 0, d[7], d[8]};
        float l[3], h[3];
        detail::TransformBox(s, boxLo, boxHi, l, h);
        if (e == 0) { std::memcpy(uLo, l, sizeof l); std::memcpy(uHi, h, sizeof h); }
        else Hull(uLo, uHi, l, h, uLo, uHi);
        const double qn = Up(SumSquaresUp(d[9], d[10], d[11]) + double(d[12]) * d[12]);
        n2 = (std::isnan(qn) || std::isnan(n2)) ? NAN : (qn > n2 ? qn : n2);
    }
    float m[3];
    for (int c = 0; c < 3; ++c) m[c] = std::fabs(uLo[c]) > std::fabs(uHi[c]) ? uLo[c] : uHi[c];  // no NaN here
    const double rho = Up(std::sqrt(SumSquaresUp(m[0], m[1], m[2])));
    double gain = Up(2 * n2 - 1);  // 2 * n2 is exact (or inf)
    if (!(gain >= 1)) gain = std::isnan(gain) ? INFINITY : 1;
    double radius = Up(gain * rho);
    if (std::isnan(radius)) radius = INFINITY;  // inf * 0
    for (int c = 0; c < 3; ++c) {
        const float t0 = srt[0][13 + c], t1 = srt[1][13 + c];
        if (std::isnan(t0) || std::isnan(t1)) { lo[c] = -INFINITY; hi[c] = INFINITY; continue; }
        lo[c] = RoundDown(Down(double(t0 < t1 ? t0 : t1) - radius));  // NaN (inf - inf) -> -inf
        hi[c] = RoundUp(Up(double(t0 < t1 ? t1 : t0) + radius));
    }
}

}  // namespace

MotionRecord LocateMotionInstance(const InstanceGeometryView& view, uint32_t i) {
    MotionRecord rec;
    const auto* base = static_cast<const uint8_t*>(view.data);
    const uint64_t bytes = base ? view.dataBytes : 0;
    const uint64_t elem = view.arrayOfPointers ? sizeof(const void*) : kMotionInstanceStride;
    const uint64_t need = view.arrayOfPointers ? sizeof(const void*) : kMotionInstanceBytes;
    const uint64_t off = uint64_t(view.range.primitiveOffset) + uint64_t(i) * elem;
    if (off > bytes || bytes - off < need) return rec;  // Unreadable
    const uint8_t* p = base + off;
    uint32_t type;
    if (view.arrayOfPointers) {
        uintptr_t ptr;
        std::memcpy(&ptr, p, sizeof ptr);
        type = uint32_t(ptr & 0xFu);
        ptr &= ~uintptr_t(0xF);
        if (ptr == 0) { rec.status = MotionRecord::NullPointer; return rec; }
        rec.body = reinterpret_cast<const uint8_t*>(ptr);
    } else {
        type = LoadU32(p);
        rec.flags = LoadU32(p + 4);
        rec.body = p + kBodyAt;
    }
    if (type > uint32_t(MotionKind::Srt)) { rec.status = MotionRecord::InvalidType; rec.body = nullptr; return rec; }
    rec.kind = MotionKind(type);
    rec.status = MotionRecord::Ok;
    return rec;
}

uint64_t MotionReference(const MotionRecord& rec) {
    uint64_t reference;
    std::memcpy(&reference, rec.body + ReferenceAt(rec.kind), 8);
    return reference;
}

void MotionInstanceBox(const MotionRecord& rec, const float blasLo[3], const float blasHi[3], bool degenerate,
                       float lo[3], float hi[3]) {
    switch (rec.kind) {
        case MotionKind::Static: {
            float m[12];
            std::memcpy(m, rec.body, sizeof m);
            if (degenerate) {
                const float t[3] = {m[3], m[7], m[11]};
                PointBox(t, lo, hi);
            } else {
                detail::TransformBox(m, blasLo, blasHi, lo, hi);
            }
            return;
        }
        case MotionKind::Matrix: MatrixBox(rec.body, blasLo, blasHi, degenerate, lo, hi); return;
        case MotionKind::Srt: SrtBox(rec.body, blasLo, blasHi, degenerate, lo, hi); return;
    }
}

}  // namespace asval::builder::detail
