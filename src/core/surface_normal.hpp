// surface_normal.hpp: the pixel normal for C++ (the host's normals, the scalar references):
// kernels/shared/surface_normal.cl itself, included here so the two cannot drift.
#pragma once

#include <algorithm>
#include <cmath>

namespace hfvis::detail {

using std::clamp;
using std::isnan;
#include "../../kernels/shared/surface_normal.cl"

}  // namespace hfvis::detail
