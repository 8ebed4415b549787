#include "exact.h"

#include <cstring>

namespace exact {
namespace {

constexpr int kLimbs = 22;       // 32-bit digits held in int64: 704 bits
constexpr int kOffset = 320;     // bit 0 of the accumulator is 2^-320 (smallest product LSB is 2^-298)

struct Accumulator {
    int64_t limb[kLimbs] = {};
    // Adds sign * mant * 2^exp (mant < 2^49).
    void Add(int sign, uint64_t mant, int exp) {
        const int bit = exp + kOffset;
        const int li = bit / 32;
        const int sh = bit % 32;
        // Spread the shifted mantissa (up to 49 + 31 bits) over three digits.
        const uint64_t a = (mant & 0xFFFFFFFFull) << sh;  // < 2^63
        const uint64_t b = (mant >> 32) << sh;            // < 2^48
        const int64_t d[3] = {int64_t(a & 0xFFFFFFFFull), int64_t((a >> 32) + (b & 0xFFFFFFFFull)), int64_t(b >> 32)};
        for (int k = 0; k < 3 && li + k < kLimbs; ++k) limb[li + k] += sign * d[k];
    }
    int Sign() {
        for (int i = 0; i + 1 < kLimbs; ++i) {
            const int64_t carry = limb[i] >> 32;  // arithmetic shift: floor division
            limb[i] -= carry * (int64_t(1) << 32);
            limb[i + 1] += carry;
        }
        if (limb[kLimbs - 1] != 0) return limb[kLimbs - 1] > 0 ? 1 : -1;
        for (int i = kLimbs - 2; i >= 0; --i)
            if (limb[i] != 0) return 1;
        return 0;
    }
};

// f = (-1)^s * m * 2^e with integer m < 2^24.
void Split(float f, int* s, uint64_t* m, int* e) {
    uint32_t b;
    std::memcpy(&b, &f, 4);
    *s = (b >> 31) ? -1 : 1;
    const uint32_t ex = (b >> 23) & 0xFF, fr = b & 0x7FFFFF;
    if (ex == 0) { *m = fr; *e = -149; }
    else { *m = fr | 0x800000u; *e = int(ex) - 150; }
}

}  // namespace

int SignAffineMinus(const float row[4], const float xyz[3], float b) {
    Accumulator acc;
    for (int c = 0; c < 3; ++c) {
        int s1, e1, s2, e2;
        uint64_t m1, m2;
        Split(row[c], &s1, &m1, &e1);
        Split(xyz[c], &s2, &m2, &e2);
        acc.Add(s1 * s2, m1 * m2, e1 + e2);
    }
    int s, e;
    uint64_t m;
    Split(row[3], &s, &m, &e);
    acc.Add(s, m, e);
    Split(b, &s, &m, &e);
    acc.Add(-s, m, e);
    return acc.Sign();
}

}  // namespace exact
