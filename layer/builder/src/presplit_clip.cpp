// Spatial midpoint splits of one triangle reference (see presplit_clip.h).
//
// Why each piece still holds its part of the exact triangle T: a piece's polygon is T clipped, in double,
// by the split planes on its path, each moved outward by `margin` (2^-40 x the largest coordinate, m).
// Invariant: every exact point y of T inside the piece's cell has a point of the computed polygon within
// e_k of it in every coordinate, where e_0 ~ 2^-50 m (the fetched triangle, see presplit.cpp) and each clip
// adds at most a few ulps (~2^-49 m): a point within e of y lies within e of the plane when y is on the
// kept side, so it survives a clip at the plane + margin while e < margin, and the clip's own rounding
// moves the polygon's vertices (hence their convex combinations) by the per-clip error: |t| <= 1 and
// |da - db| = |da| + |db| (no cancellation), so a clipped vertex is off by < 16 ulps of m, 2^-48 m. A path
// holds at most kMaxClips = 64 clips (deeper pieces are kept whole), so e_k < 2^-41 m < margin. The piece box is the
// polygon's bounds widened by the margin, rounded outward and intersected with the cell: it contains y.
// An empty polygon or box therefore means no point of T is in the cell, and only then is a piece dropped.
#include "presplit_clip.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bvh_internal.h"

namespace asval::builder::detail {
namespace {

constexpr uint32_t kMaxClips = 64;  // split levels on one path; bounds the accumulated clipping error

double Area(const float lo[3], const float hi[3]) {
    double e[3];
    for (int a = 0; a < 3; ++a) e[a] = std::max(0.0, double(hi[a]) - double(lo[a]));
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

// Directed rounding of three doubles (xy in one register, z in the low lane of another) to the float
// lanes 0..2: the largest float <= d (Down) or the smallest float >= d (Up); lane 3 is junk. As float(d)
// stepped one ulp with std::nextafter when it rounded past d, but branch-free and 3 lanes at once (the
// step's direction is random: mispredicting it made the scalar form the splitter's largest cost). d is
// never NaN here (candidates have finite boxes). One ulp towards -inf is bits - 1 for a positive float
// (+inf -> FLT_MAX) and bits + 1 for a negative one (-0 -> -denormal_min; a d below zero never rounds to
// +0); towards +inf the reverse (+0 -> denormal_min).
template <bool Up>
inline __m128 RoundOutward(__m128d xy, __m128d z) {
    const __m128 f = _mm_movelh_ps(_mm_cvtpd_ps(xy), _mm_cvtpd_ps(z));
    const __m128d backXy = _mm_cvtps_pd(f), backZ = _mm_cvtps_pd(_mm_movehl_ps(f, f));
    const __m128d pastXy = Up ? _mm_cmplt_pd(backXy, xy) : _mm_cmpgt_pd(backXy, xy);
    const __m128d pastZ = Up ? _mm_cmplt_sd(backZ, z) : _mm_cmpgt_sd(backZ, z);
    // 64-bit lane masks -> 32-bit lanes 0..2 (lane 3 from z's upper lane: junk, never used).
    const __m128i past = _mm_castps_si128(_mm_shuffle_ps(_mm_castpd_ps(pastXy), _mm_castpd_ps(pastZ), _MM_SHUFFLE(2, 0, 2, 0)));
    const __m128i bits = _mm_castps_si128(f);
    const __m128i negative = _mm_srai_epi32(bits, 31);  // -1 for a negative float, else 0
    const __m128i one = _mm_set1_epi32(1);
    // Up: +1 for positive, -1 for negative = 1 + 2 * negative; down: the opposite.
    const __m128i upStep = _mm_add_epi32(one, _mm_add_epi32(negative, negative));
    const __m128i step = Up ? upStep : _mm_sub_epi32(_mm_setzero_si128(), upStep);
    return _mm_castsi128_ps(_mm_add_epi32(bits, _mm_and_si128(step, past)));
}

// Keeps the part of `in` with sign * (x[axis] - c) <= 0; false if the result would exceed Poly::kMax.
bool ClipPlane(const Poly& in, int axis, double c, double sign, Poly* out) {
    int n = 0;
    for (int i = 0; i < in.n; ++i) {
        const double* a = in.v[i];
        const double* b = in.v[i + 1 == in.n ? 0 : i + 1];  // not `% n`: a division per edge showed in profiles
        const double da = sign * (a[axis] - c), db = sign * (b[axis] - c);
        if (da <= 0) {
            if (n == Poly::kMax) return false;
            std::memcpy(out->v[n++], a, sizeof(double) * 3);
        }
        if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
            if (n == Poly::kMax) return false;
            const double t = da / (da - db);
            double* p = out->v[n++];
            for (int k = 0; k < 3; ++k) p[k] = a[k] + t * (b[k] - a[k]);
            p[axis] = c;
        }
    }
    out->n = n;
    return true;
}

}  // namespace

PieceSplitter::PieceSplitter(const double tri[3][3], double margin, double threshold)
    : margin_(margin), threshold_(threshold) {
    tri_.n = 3;
    std::memcpy(tri_.v, tri, sizeof(double) * 9);
}

void PieceSplitter::Split(const PrimRef& box, uint32_t cap, std::vector<PrimRef>* out) const {
    SplitPiece(tri_, box, cap, 0, out);
}

void PieceSplitter::SplitPiece(const Poly& poly, const PrimRef& box, uint32_t cap, uint32_t depth,
                               std::vector<PrimRef>* out) const {
    if (cap <= 1 || depth == kMaxClips || Area(box.lo, box.hi) <= threshold_) { out->push_back(box); return; }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (double(box.hi[a]) - box.lo[a] > double(box.hi[axis]) - box.lo[axis]) axis = a;
    const float mid = float(0.5 * (double(box.lo[axis]) + double(box.hi[axis])));
    if (!(mid > box.lo[axis] && mid < box.hi[axis])) { out->push_back(box); return; }
    Poly halves[2];
    PrimRef cells[2] = {box, box};
    cells[0].hi[axis] = mid;
    cells[1].lo[axis] = mid;
    if (!ClipPlane(poly, axis, double(mid) + margin_, 1.0, &halves[0]) ||
        !ClipPlane(poly, axis, double(mid) - margin_, -1.0, &halves[1])) {
        out->push_back(box);  // pathological rounding: keep the whole (conservative) box
        return;
    }
    PrimRef kept[2];
    int keptHalf[2];
    int n = 0;
    for (int h = 0; h < 2; ++h)
        if (halves[h].n > 0 && Bound(halves[h], cells[h], &kept[n])) keptHalf[n++] = h;
    if (n == 0) { out->push_back(box); return; }  // cannot happen for a non-empty part; stay safe
    if (n == 1) { SplitPiece(halves[keptHalf[0]], kept[0], cap, depth + 1, out); return; }
    SplitPiece(halves[0], kept[0], cap / 2, depth + 1, out);
    SplitPiece(halves[1], kept[1], cap - cap / 2, depth + 1, out);
}

bool PieceSplitter::Bound(const Poly& poly, const PrimRef& cell, PrimRef* piece) const {
    __m128d loXy = _mm_loadu_pd(poly.v[0]), hiXy = loXy;
    __m128d loZ = _mm_load_sd(&poly.v[0][2]), hiZ = loZ;
    for (int i = 1; i < poly.n; ++i) {
        const __m128d xy = _mm_loadu_pd(poly.v[i]), z = _mm_load_sd(&poly.v[i][2]);
        loXy = _mm_min_pd(loXy, xy);
        hiXy = _mm_max_pd(hiXy, xy);
        loZ = _mm_min_sd(loZ, z);
        hiZ = _mm_max_sd(hiZ, z);
    }
    const __m128d margin = _mm_set1_pd(margin_);
    const __m128 lo = RoundOutward<false>(_mm_sub_pd(loXy, margin), _mm_sub_sd(loZ, margin));
    const __m128 hi = RoundOutward<true>(_mm_add_pd(hiXy, margin), _mm_add_sd(hiZ, margin));
    // max(lo, cell) / min(hi, cell) with the cell's value kept on a tie, as std::max(cell, x) /
    // std::min(cell, x) do (a +-0 tie keeps the cell's zero).
    const __m128 cellLo = LoadLo(cell), cellHi = LoadHi(cell);
    const __m128 outLo = _mm_max_ps(lo, cellLo), outHi = _mm_min_ps(hi, cellHi);
    if (_mm_movemask_ps(_mm_cmpgt_ps(outLo, outHi)) & 7) return false;
    // Lane 3 of each half is the id / aux: keep the cell's.
    const __m128 keep3 = _mm_castsi128_ps(_mm_set_epi32(-1, 0, 0, 0));
    _mm_store_ps(piece->lo, _mm_or_ps(_mm_andnot_ps(keep3, outLo), _mm_and_ps(keep3, cellLo)));
    _mm_store_ps(piece->hi, _mm_or_ps(_mm_andnot_ps(keep3, outHi), _mm_and_ps(keep3, cellHi)));
    return true;
}

}  // namespace asval::builder::detail
