#include "fast_math_probe.h"

namespace fastmathprobe {

bool BuiltWithFastMath() {
#ifdef __FAST_MATH__
    return true;
#else
    return false;
#endif
}

bool ValueNaNTest(float x) { return x != x; }

}  // namespace fastmathprobe
