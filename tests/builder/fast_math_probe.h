// Compiled into asval_builder_fastmath only, with that library's flags (-ffast-math): lets the canary test
// prove that the copy it links really is a fast-math build, one in which a value-based NaN test is gone.
#pragma once

namespace fastmathprobe {

// True when this translation unit was compiled with -ffast-math (__FAST_MATH__).
bool BuiltWithFastMath();
// `x != x`, compiled with the library copy's flags: under -ffinite-math-only it folds to false.
bool ValueNaNTest(float x);

}  // namespace fastmathprobe
