// Private: raw loads and the per-format traits the classifier's loops are instantiated on.
// Everything here works on source bits; no floating-point arithmetic touches a value before its NaN test.
#pragma once

#include <cstdint>
#include <cstring>

namespace asval::builder::detail {

inline uint16_t LoadU16(const uint8_t* p) { uint16_t v; std::memcpy(&v, p, 2); return v; }
inline uint32_t LoadU32(const uint8_t* p) { uint32_t v; std::memcpy(&v, p, 4); return v; }
inline float LoadF32(const uint8_t* p) { float v; std::memcpy(&v, p, 4); return v; }

inline bool F32BitsNaN(uint32_t b) { return (b & 0x7FFFFFFFu) > 0x7F800000u; }
inline bool F16BitsNaN(uint32_t h) { return (h & 0x7FFFu) > 0x7C00u; }

// Exact binary16 -> binary32 (every half value is representable in float).
inline float HalfToFloat(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16;
    const uint32_t exp = (h >> 10) & 0x1Fu;
    const uint32_t mant = h & 0x3FFu;
    uint32_t bits;
    if (exp == 0x1Fu) {
        bits = sign | 0x7F800000u | (mant << 13);  // inf / NaN (payload kept, stays NaN)
    } else if (exp != 0) {
        bits = sign | ((exp + 112u) << 23) | (mant << 13);
    } else if (mant == 0) {
        bits = sign;
    } else {
        // Subnormal: mant * 2^-24 is exact in float.
        float f = float(mant) * 0x1p-24f;
        std::memcpy(&bits, &f, 4);
        bits |= sign;
    }
    float out;
    std::memcpy(&out, &bits, 4);
    return out;
}

// Spec conversions (fundamentals, "Fixed-Point Data Conversions"); float division is correctly rounded.
inline float SnormToFloat(int32_t code, unsigned bits) {
    const int32_t maxCode = (1 << (bits - 1)) - 1;
    if (code < -maxCode) code = -maxCode;  // max(c / max, -1): the clamp, done on the code
    return float(code) / float(maxCode);
}
inline float UnormToFloat(uint32_t code, unsigned bits) {
    return float(code) / float((1u << bits) - 1u);
}

// ---- Equality keys. Two components' keys are equal iff their decoded values are equal, for every
// non-NaN input (NaN is handled by the caller's slow path, where it compares unequal).
inline uint32_t F32Key(uint32_t b) { return (b << 1) == 0 ? 0u : b; }        // +0 == -0
inline uint32_t F16Key(uint32_t h) { return (h & 0x7FFFu) == 0 ? 0u : h; }   // +0 == -0
inline uint32_t SnormKey(int32_t code, unsigned bits) {
    const int32_t maxCode = (1 << (bits - 1)) - 1;
    return uint32_t(code < -maxCode ? -maxCode : code);
}

}  // namespace asval::builder::detail
