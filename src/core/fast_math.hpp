// fast_math.hpp: the kernels' polynomial atan and sin for C++ (the scalar references):
// kernels/shared/fast_math.cl itself, included here so the two cannot drift.
#pragma once

#include <cmath>

namespace hfvis::detail {

using std::fabs;
using std::rint;
#include "../../kernels/shared/fast_math.cl"

constexpr float kPiF = HFVIS_PI_F;

inline float hfMin(float a, float b) { return hf_min(a, b); }
inline float hfMax(float a, float b) { return hf_max(a, b); }
inline float hfAtan(float x) { return hf_atan(x); }
inline float hfSin(float x) { return hf_sin(x); }

}  // namespace hfvis::detail
