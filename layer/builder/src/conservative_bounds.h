// Private: directed rounding helpers shared by the bounds code.
#pragma once

namespace asval::builder::detail {

float RoundDown(double d);  // largest float <= d (NaN: -inf)
float RoundUp(double d);    // smallest float >= d (NaN: +inf)
void RowInterval(const float row[4], const float lo[3], const float hi[3], float* outLo, float* outHi);
// TransformBoxConservative without the float-mode guard, for callers that already hold one.
void TransformBox(const float m[12], const float lo[3], const float hi[3], float outLo[3], float outHi[3]);

}  // namespace asval::builder::detail
