// Exact arithmetic for the containment property tests: the sign of row . [x, y, z, 1] - b for float
// inputs, computed with a 640-bit fixed-point accumulator (no rounding anywhere). Independent of the
// builder's double-plus-margin method, which is what it checks.
#pragma once

#include <cstdint>

namespace exact {

// -1, 0 or +1: the sign of m0*x + m1*y + m2*z + m3 - b, exactly. All inputs must be finite.
int SignAffineMinus(const float row[4], const float xyz[3], float b);

}  // namespace exact
