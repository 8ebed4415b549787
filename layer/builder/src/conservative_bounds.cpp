// Outward-rounded transforms. This file is compiled with -ffp-contract=off (see CMakeLists.txt): an FMA
// would change the rounding the error bound below assumes.
#include <cfloat>
#include <cmath>

#include "asval/builder/build_input.h"
#include "conservative_bounds.h"
#include "float_mode.h"

namespace asval::builder {
namespace detail {

float RoundDown(double d) {
    if (std::isnan(d)) return -INFINITY;
    float f = float(d);
    if (double(f) > d) f = std::nextafter(f, -INFINITY);
    return f;
}

float RoundUp(double d) {
    if (std::isnan(d)) return INFINITY;
    float f = float(d);
    if (double(f) < d) f = std::nextafter(f, INFINITY);
    return f;
}

// Error-free addition (Knuth's TwoSum): s + err == a + b exactly.
inline double TwoSum(double a, double b, double* err) {
    const double s = a + b;
    const double bb = s - a;
    *err = (a - (s - bb)) + (b - bb);
    return s;
}

// Interval of row . [x, y, z, 1] over x in [lo0, hi0], ... Each product of two floats is exact in double
// (24 + 24 significant bits). The three additions are error-free transformed: when every error is zero the
// double sum is exact and only the final rounding to float (directed) remains. Otherwise each error is at
// most 2^-53 of its partial sum, so the total is below 3 * 2^-53 * sum|terms|; we widen by 2^-50 * sum|terms|
// (the widening's own rounding is covered by the slack) and round outward.
void RowInterval(const float row[4], const float lo[3], const float hi[3], float* outLo, float* outHi) {
    double sLo = row[3], sHi = row[3], mag = std::fabs(double(row[3]));
    bool exactLo = true, exactHi = true;
    for (int c = 0; c < 3; ++c) {
        const double a = double(row[c]) * double(lo[c]);
        const double b = double(row[c]) * double(hi[c]);
        if (std::isnan(a) || std::isnan(b)) { sLo = sHi = NAN; continue; }  // NaN matrix, 0 * inf
        const double mn = a < b ? a : b, mx = a < b ? b : a;
        double e;
        sLo = TwoSum(sLo, mn, &e);
        exactLo &= e == 0;
        sHi = TwoSum(sHi, mx, &e);
        exactHi &= e == 0;
        mag += std::fabs(mn) > std::fabs(mx) ? std::fabs(mn) : std::fabs(mx);
    }
    const double margin = mag * 0x1p-50;
    // NaN anywhere (NaN in the matrix, inf * 0, inf - inf) ends as an infinite bound via RoundDown/RoundUp.
    *outLo = RoundDown(exactLo ? sLo : sLo - margin);
    *outHi = RoundUp(exactHi ? sHi : sHi + margin);
}

void TransformBox(const float m[12], const float lo[3], const float hi[3], float outLo[3], float outHi[3]) {
    for (int r = 0; r < 3; ++r) RowInterval(m + 4 * r, lo, hi, &outLo[r], &outHi[r]);
}

}  // namespace detail

void TransformBoxConservative(const float m[12], const float lo[3], const float hi[3], float outLo[3],
                              float outHi[3]) {
    const detail::FloatModeGuard mode;
    detail::TransformBox(m, lo, hi, outLo, outHi);
}

}  // namespace asval::builder
