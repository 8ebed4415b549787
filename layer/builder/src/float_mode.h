// Private: the floating-point mode the builder's arithmetic assumes. Conservative bounds rely on
// round-to-nearest and on subnormals being kept: with flush-to-zero / denormals-are-zero (which games and
// fast-math programs set, and the layer runs on their threads) a 1e-40 coordinate would become 0 and fall
// outside its own box, and two distinct subnormal vertices would compare equal. Every public entry point
// that computes with floats holds a FloatModeGuard: it sets the IEEE default for the call and gives the
// caller its own mode (and exception flags) back on return. Threads the builder starts take a guard too.
#pragma once

#if defined(__SSE2__) || defined(_M_X64)
#include <xmmintrin.h>
#endif

namespace asval::builder::detail {

class FloatModeGuard {
public:
#if defined(__SSE2__) || defined(_M_X64)
    // MXCSR: all exceptions masked, round to nearest, no flush-to-zero, no denormals-are-zero.
    static constexpr unsigned kDefault = 0x1F80u;
    FloatModeGuard() : saved_(_mm_getcsr()) { _mm_setcsr(kDefault); }
    ~FloatModeGuard() { _mm_setcsr(saved_); }

private:
    unsigned saved_;
#else
    FloatModeGuard() {}
#endif
public:
    FloatModeGuard(const FloatModeGuard&) = delete;
    FloatModeGuard& operator=(const FloatModeGuard&) = delete;
};

}  // namespace asval::builder::detail
