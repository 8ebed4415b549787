// Exact dyadic rationals (m * 2^e, m a big integer) for the motion containment tests: sums and products of
// floats and integers with no rounding anywhere. Independent of the builder's bounds code, which it checks.
// Capacity: 768-bit magnitudes (ample for the tests' inputs); exceeding it sets Overflowed() and the
// tests fail rather than compare a wrong value.
#pragma once

#include <cstdint>

namespace exact {

class Dyadic {
public:
    Dyadic() = default;
    static Dyadic FromFloat(float f);  // f finite
    static Dyadic FromInt(int64_t v);
    Dyadic operator+(const Dyadic& o) const;
    Dyadic operator-(const Dyadic& o) const;
    Dyadic operator*(const Dyadic& o) const;
    int Sign() const { return len_ == 0 ? 0 : neg_ ? -1 : 1; }
    static bool Overflowed();
    static void ResetOverflow();

private:
    static constexpr int kLimbs = 24;
    bool neg_ = false;
    int exp_ = 0;  // value = (-1)^neg * sum limb[i] 2^(32 i) * 2^exp
    int len_ = 0;  // used limbs; 0 means zero
    uint32_t limb_[kLimbs] = {};
    void Trim();
    static Dyadic AddMagnitudes(const Dyadic& a, const Dyadic& b, bool negateB);
};

// -1, 0, +1: sign of a - b.
inline int Compare(const Dyadic& a, const Dyadic& b) { return (a - b).Sign(); }

}  // namespace exact
