// fast_math.hpp: scalar mirrors of kernels/fast_math.cl, operation for operation (the
// build disables FP contraction), so references round exactly as the kernels do.
#pragma once

#include <cmath>

namespace hfvis::detail {

constexpr float kPiF = 3.14159265358979323846f;

// Mirrors of hf_min / hf_max (compare and select).
inline float hfMin(float a, float b) { return a < b ? a : b; }
inline float hfMax(float a, float b) { return a > b ? a : b; }

inline float hfAtan(float x) {
  const float a = std::fabs(x);
  const bool big = a > 2.414213562373095f;
  const bool mid = a > 0.4142135623730950f;
  const float reduced = big ? -1.0f / a : (mid ? (a - 1.0f) / (a + 1.0f) : a);
  const float base = big ? 0.5f * kPiF : (mid ? 0.25f * kPiF : 0.0f);
  const float z = reduced * reduced;
  const float p =
      (((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z;
  const float y = base + (p * reduced + reduced);
  return x < 0.0f ? -y : y;
}


inline float hfSin(float x) {
  float r = x - 2.0f * kPiF * std::rint(x * (0.5f / kPiF));
  r = r > 0.5f * kPiF ? kPiF - r : r;
  r = r < -0.5f * kPiF ? -kPiF - r : r;
  const float z = r * r;
  const float p = ((((-2.5052108385e-8f * z + 2.7557319224e-6f) * z - 1.9841269841e-4f) * z + 8.3333333333e-3f) * z -
                   1.6666666667e-1f) *
                  z;
  return p * r + r;
}

}  // namespace hfvis::detail
