// chord_side.hpp: the one geometric predicate of the intervisibility operation, decided
// exactly: on which side of the chord from a to c a line sample b lies. Mirrors
// chord_side() in kernels/intervisibility.cl operation by operation.
//
// Why exact: the convex hull tree keeps structure that was decided under earlier
// receivers, and visible counts are integers compared exactly against a brute-force
// enumeration and the naive march. With rounded predicates the tree and the enumeration
// disagree on near-collinear samples (terraces, tilted planes at large offsets), and the
// tree's invariants (a concave sample's slot is free when the next leaf needs it) can
// break. Exact signs make every decision consistent, in the kernel, in the reference and
// in the oracles, on any device with IEEE single precision (+, -, * and fma correctly
// rounded, as OpenCL requires) and gradual underflow (devices that flush denormals to
// zero may differ on heights below 1e-38).
#pragma once

#include <cmath>

namespace hfvis::detail {

// Relative error bound of the float filter (Shewchuk's orient2d bound for p = 24 bits).
constexpr float kChordSideErrorBound = (3.0f + 16.0f * 0x1p-24f) * 0x1p-24f;
// Below this magnitude the filter's relative error model may fail through underflow.
constexpr float kChordSideFilterFloor = 0x1p-100f;

// a + b = s + err exactly (Knuth's branch-free TwoSum).
inline void twoSum(float a, float b, float& s, float& err) {
  s = a + b;
  const float bb = s - a;
  err = (a - (s - bb)) + (b - bb);
}

// Adds b to the nonoverlapping expansion e[0..n) (increasing magnitude), in place,
// giving n + 1 components (Shewchuk's Grow-Expansion; exact, may leave zeros).
inline void growExpansion(float* e, int n, float b) {
  float q = b;
  for (int i = 0; i < n; ++i) {
    float s, err;
    twoSum(q, e[i], s, err);
    e[i] = err;
    q = s;
  }
  e[n] = q;
}

// Exact sign of hb * dac - ha * dbc - hc * dab: three products split exactly by fma into
// (product, rounding error), summed as an expansion whose largest nonzero component has
// the sign of the whole.
inline int exactChordSide(float ha, float hb, float hc, float dab, float dbc, float dac) {
  float e[6];
  const float p1 = hb * dac, p2 = ha * dbc, p3 = hc * dab;
  e[0] = std::fma(hb, dac, -p1);
  e[1] = p1;
  growExpansion(e, 2, -std::fma(ha, dbc, -p2));
  growExpansion(e, 3, -p2);
  growExpansion(e, 4, -std::fma(hc, dab, -p3));
  growExpansion(e, 5, -p3);
  for (int i = 5; i >= 0; --i)
    if (e[i] != 0.0f) return e[i] > 0.0f ? 1 : -1;
  return 0;
}

// Sign of the position of sample b relative to the chord from sample a to sample c on one
// line: +1 strictly above, 0 on it, -1 strictly below. a, b, c are in line order with
// b - a = dab > 0 and c - b = dbc > 0 steps (integers below 2^24, so that dab + dbc is
// exact); heights are finite with |h| * (dab + dbc) below FLT_MAX. A float filter decides
// almost every call; ties and near-ties fall through to the exact expansion.
inline int chordSide(float ha, float hb, float hc, float dab, float dbc) {
  if (ha == hc && hb == hc) return 0;  // flat runs: the most common tie, decided at once
  const float dac = dab + dbc;
  const float p1 = (hb - hc) * dac;
  const float p2 = (ha - hc) * dbc;
  const float det = p1 - p2;
  const float magnitude = std::fabs(p1) + std::fabs(p2);
  if (magnitude >= kChordSideFilterFloor) {
    const float bound = kChordSideErrorBound * magnitude;
    if (det > bound) return 1;
    if (-det > bound) return -1;
  }
  return exactChordSide(ha, hb, hc, dab, dbc, dac);
}

}  // namespace hfvis::detail
