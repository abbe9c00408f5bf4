// direction_terms.hpp: the horizon operation's per-direction terms (elevation, sky view,
// ambient occlusion) for C++: kernels/shared/direction_terms.cl itself, included here so the scalar
// references and the kernels cannot drift.
#pragma once

#include <cmath>

#include "core/fast_math.hpp"

namespace hfvis::detail {

using std::sqrt;
#include "../../kernels/shared/direction_terms.cl"
HFVIS_DIRECTION_TERMS(float, int)

}  // namespace hfvis::detail
