#include "exact_dyadic.h"

#include <cstring>

namespace exact {
namespace {

bool gOverflow = false;

// Magnitude helpers on little-endian 32-bit limbs.
int CompareMag(const uint32_t* a, int na, const uint32_t* b, int nb) {
    if (na != nb) return na < nb ? -1 : 1;
    for (int i = na - 1; i >= 0; --i)
        if (a[i] != b[i]) return a[i] < b[i] ? -1 : 1;
    return 0;
}

}  // namespace

bool Dyadic::Overflowed() { return gOverflow; }
void Dyadic::ResetOverflow() { gOverflow = false; }

void Dyadic::Trim() {
    while (len_ > 0 && limb_[len_ - 1] == 0) --len_;
    int z = 0;
    while (z < len_ && limb_[z] == 0) ++z;  // whole zero limbs at the bottom: fold into the exponent
    if (z > 0) {
        std::memmove(limb_, limb_ + z, sizeof(uint32_t) * size_t(len_ - z));
        for (int i = len_ - z; i < len_; ++i) limb_[i] = 0;
        len_ -= z;
        exp_ += 32 * z;
    }
    if (len_ == 0) { neg_ = false; exp_ = 0; }
}

Dyadic Dyadic::FromFloat(float f) {
    uint32_t b;
    std::memcpy(&b, &f, 4);
    const uint32_t ex = (b >> 23) & 0xFF, fr = b & 0x7FFFFF;
    Dyadic d;
    d.neg_ = (b >> 31) != 0;
    d.limb_[0] = ex == 0 ? fr : (fr | 0x800000u);
    d.exp_ = ex == 0 ? -149 : int(ex) - 150;
    d.len_ = 1;
    d.Trim();
    return d;
}

Dyadic Dyadic::FromInt(int64_t v) {
    Dyadic d;
    d.neg_ = v < 0;
    const uint64_t m = v < 0 ? uint64_t(0) - uint64_t(v) : uint64_t(v);
    d.limb_[0] = uint32_t(m);
    d.limb_[1] = uint32_t(m >> 32);
    d.len_ = 2;
    d.Trim();
    return d;
}

// Aligns both to the smaller exponent (a left shift of the other's magnitude), then adds or subtracts.
Dyadic Dyadic::AddMagnitudes(const Dyadic& a, const Dyadic& b, bool negateB) {
    const bool bNeg = b.neg_ != negateB;
    if (b.len_ == 0) return a;
    if (a.len_ == 0) { Dyadic r = b; r.neg_ = bNeg; return r; }
    const int e = a.exp_ < b.exp_ ? a.exp_ : b.exp_;
    uint32_t x[kLimbs + 1] = {}, y[kLimbs + 1] = {};
    auto shifted = [&](const Dyadic& d, uint32_t* out) -> int {
        const int bits = d.exp_ - e, words = bits / 32, sh = bits % 32;
        if (d.len_ + words + 1 > kLimbs) { gOverflow = true; return 0; }
        for (int i = 0; i < d.len_; ++i) {
            const uint64_t v = uint64_t(d.limb_[i]) << sh;
            out[i + words] |= uint32_t(v);
            out[i + words + 1] |= uint32_t(v >> 32);
        }
        return d.len_ + words + 1;
    };
    int nx = shifted(a, x), ny = shifted(b, y);
    while (nx > 0 && x[nx - 1] == 0) --nx;
    while (ny > 0 && y[ny - 1] == 0) --ny;
    Dyadic r;
    r.exp_ = e;
    if (a.neg_ == bNeg) {
        const int n = nx > ny ? nx : ny;
        if (n + 1 > kLimbs) { gOverflow = true; return r; }
        uint64_t carry = 0;
        for (int i = 0; i < n; ++i) {
            const uint64_t s = uint64_t(x[i]) + y[i] + carry;
            r.limb_[i] = uint32_t(s);
            carry = s >> 32;
        }
        r.limb_[n] = uint32_t(carry);
        r.len_ = n + 1;
        r.neg_ = a.neg_;
    } else {
        const int c = CompareMag(x, nx, y, ny);
        if (c == 0) return Dyadic{};
        const uint32_t* big = c > 0 ? x : y;
        const uint32_t* small = c > 0 ? y : x;
        const int n = c > 0 ? nx : ny;
        int64_t borrow = 0;
        for (int i = 0; i < n; ++i) {
            int64_t s = int64_t(big[i]) - int64_t(small[i]) - borrow;
            borrow = s < 0;
            if (s < 0) s += int64_t(1) << 32;
            r.limb_[i] = uint32_t(s);
        }
        r.len_ = n;
        r.neg_ = c > 0 ? a.neg_ : bNeg;
    }
    r.Trim();
    return r;
}

Dyadic Dyadic::operator+(const Dyadic& o) const { return AddMagnitudes(*this, o, false); }
Dyadic Dyadic::operator-(const Dyadic& o) const { return AddMagnitudes(*this, o, true); }

Dyadic Dyadic::operator*(const Dyadic& o) const {
    Dyadic r;
    if (len_ == 0 || o.len_ == 0) return r;
    if (len_ + o.len_ > kLimbs) { gOverflow = true; return r; }
    for (int i = 0; i < len_; ++i) {
        uint64_t carry = 0;
        for (int j = 0; j < o.len_; ++j) {
            const uint64_t t = uint64_t(limb_[i]) * o.limb_[j] + r.limb_[i + j] + carry;
            r.limb_[i + j] = uint32_t(t);
            carry = t >> 32;
        }
        r.limb_[i + o.len_] = uint32_t(carry);
    }
    r.len_ = len_ + o.len_;
    r.exp_ = exp_ + o.exp_;
    r.neg_ = neg_ != o.neg_;
    r.Trim();
    return r;
}

}  // namespace exact
