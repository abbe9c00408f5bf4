// opencl_builtins.hpp: the OpenCL C built-in functions that kernels/shared/*.cl call, for the
// headers that compile those sources as C++ in hfvis::detail (the host and the scalar
// references), so the kernel and its C++ twin are one text.
#pragma once

#include <cmath>

namespace hfvis::detail {

using std::ceil;
using std::fabs;
using std::floor;
using std::fmax;
using std::fmin;
using std::isfinite;
using std::isnan;
using std::rint;
using std::sqrt;

}  // namespace hfvis::detail
