// environment_light_terms.hpp: the evaluation of an environment's tables at a receiver
// (environment_add) for C++: kernels/environment_light.cl itself, included here so the scalar
// reference and the kernels cannot drift.
#pragma once

#include <cmath>

#include "core/fast_math.hpp"

namespace hfvis::detail {

#include "../../kernels/environment_light.cl"

}  // namespace hfvis::detail
