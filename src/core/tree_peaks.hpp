// tree_peaks.hpp: the hull tree's occluder-only peaks for C++ (the scalar tree's lines, the
// references): kernels/shared/tree_peaks.cl itself, the source the kernels compile, included
// here so the two cannot drift.
#pragma once

#include <cmath>

#include "core/chord_side.hpp"
#include "core/opencl_builtins.hpp"

namespace hfvis::detail {

#ifndef NAN
#error "NAN must come from <cmath>"
#endif
#include "../../kernels/shared/tree_peaks.cl"

}  // namespace hfvis::detail
