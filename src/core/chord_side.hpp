// chord_side.hpp: the exact chord predicate of the hull tree for C++ (the scalar
// references, the horizon lists, the tests): kernels/shared/chord_side.cl itself, the source the
// kernels compile, included here so the two cannot drift.
#pragma once

#include <cmath>

namespace hfvis::detail {

using std::fabs;
using std::fma;
#include "../../kernels/shared/chord_side.cl"

// Sign of sample b relative to the chord from a to c on one line (a, b, c in line order,
// b - a = dab > 0 and c - b = dbc > 0 steps, integers below 2^24; finite heights with
// |h| * (dab + dbc) below FLT_MAX): +1 strictly above, 0 on it, -1 strictly below.
inline int chordSide(float ha, float hb, float hc, float dab, float dbc) { return chord_side(ha, hb, hc, dab, dbc); }

}  // namespace hfvis::detail
