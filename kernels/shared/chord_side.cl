// chord_side.cl: the one geometric predicate of the convex hull tree and the visibility
// marches, decided exactly: on which side of the chord from sample a to sample c a sample b
// lies. Written once in the common subset of OpenCL C and C++: kernels/intervisibility.cl
// includes it, and so does src/core/chord_side.hpp (inside namespace hfvis::detail, with fma and
// fabs from <cmath>), so the kernels, the scalar references and the tests' oracles run the
// very same operations.
//
// Why exact: the convex hull tree keeps structure that was decided under earlier
// receivers, and visible counts are integers compared exactly against a brute-force
// enumeration and the naive march. With rounded predicates the tree and the enumeration
// disagree on near-collinear samples (terraces, tilted planes at large offsets), and the
// tree's invariants (a concave sample's slot is free when the next leaf needs it) can
// break. Exact signs make every decision consistent on any device with IEEE single
// precision (+, -, * and fma correctly rounded, as OpenCL requires) and gradual underflow
// (devices that flush denormals to zero may differ on heights below 1e-38).
#ifndef HFVIS_CHORD_SIDE_CL
#define HFVIS_CHORD_SIDE_CL

#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline __attribute__((always_inline))
#endif
// The exact predicate's fallback is rare but long: inlined at every call site it made the
// sweep 30 % slower (code size), so it stays a call.
#define HFVIS_NOINLINE __attribute__((noinline))
#else  // C++: header functions, built with -ffp-contract=off
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline
#endif
#define HFVIS_NOINLINE inline
#endif

// Relative error bound of the float filter (Shewchuk's orient2d bound for p = 24 bits), and
// the magnitude below which its error model may fail through underflow.
#define HFVIS_CHORD_ERROR_BOUND ((3.0f + 16.0f * 0x1p-24f) * 0x1p-24f)
#define HFVIS_CHORD_FILTER_FLOOR 0x1p-100f

// a + b = *s + *err exactly (Knuth's branch-free TwoSum).
HFVIS_INLINE void two_sum(float a, float b, float* s, float* err) {
  float sum = a + b;
  float bb = sum - a;
  *err = (a - (sum - bb)) + (b - bb);
  *s = sum;
}

// q + e = new q + new e exactly: one step of Shewchuk's Grow-Expansion.
#define HFVIS_GROW(q, e)         \
  {                              \
    float sum_, err_;            \
    two_sum(q, e, &sum_, &err_); \
    e = err_;                    \
    q = sum_;                    \
  }

HFVIS_INLINE int sign_of(float v) { return v > 0.0f ? 1 : v < 0.0f ? -1 : 0; }

// Exact sign of hb * dac - ha * dbc - hc * dab: fma splits each product exactly into
// (product, rounding error); Grow-Expansion (Shewchuk) sums the six terms into a
// nonoverlapping expansion e0..e5 of increasing magnitude, whose largest nonzero
// component has the sign of the whole. Straight-line (unrolled, selects only): it
// keeps no private array.
HFVIS_NOINLINE int exact_chord_side(float ha, float hb, float hc, float dab, float dbc, float dac) {
  float p1 = hb * dac, p2 = ha * dbc, p3 = hc * dab;
  float e0 = fma(hb, dac, -p1), e1 = p1, e2, e3, e4, e5, q;
  q = -fma(ha, dbc, -p2);
  HFVIS_GROW(q, e0) HFVIS_GROW(q, e1) e2 = q;
  q = -p2;
  HFVIS_GROW(q, e0) HFVIS_GROW(q, e1) HFVIS_GROW(q, e2) e3 = q;
  q = -fma(hc, dab, -p3);
  HFVIS_GROW(q, e0) HFVIS_GROW(q, e1) HFVIS_GROW(q, e2) HFVIS_GROW(q, e3) e4 = q;
  q = -p3;
  HFVIS_GROW(q, e0) HFVIS_GROW(q, e1) HFVIS_GROW(q, e2) HFVIS_GROW(q, e3) HFVIS_GROW(q, e4) e5 = q;
  return e5 != 0.0f   ? sign_of(e5)
         : e4 != 0.0f ? sign_of(e4)
         : e3 != 0.0f ? sign_of(e3)
         : e2 != 0.0f ? sign_of(e2)
         : e1 != 0.0f ? sign_of(e1)
                      : sign_of(e0);
}

// Sign of sample b relative to the chord from a to c (a, b, c in line order, b - a = dab
// and c - b = dbc steps, integers below 2^24): +1 strictly above, 0 on it, -1 below.
HFVIS_INLINE int chord_side(float ha, float hb, float hc, float dab, float dbc) {
  if (ha == hc && hb == hc) return 0;
  float dac = dab + dbc;
  float p1 = (hb - hc) * dac;
  float p2 = (ha - hc) * dbc;
  float det = p1 - p2;
  float magnitude = fabs(p1) + fabs(p2);
  if (magnitude >= HFVIS_CHORD_FILTER_FLOOR) {
    float bound = HFVIS_CHORD_ERROR_BOUND * magnitude;
    if (det > bound) return 1;
    if (-det > bound) return -1;
  }
  return exact_chord_side(ha, hb, hc, dab, dbc, dac);
}

// The heights' rounding, which the tie rule forgives (docs/ALGORITHMS.md, "Grazing samples and
// the heights' rounding"). A sample's height is a bilinear interpolation rounded to a float, a
// few units in the last place of the heights off the surface, and the heights themselves were
// rounded to float32 at their absolute value (the kernels see them less the field's base,
// `base`: the height of their 0). On a tilted plane that tips collinear samples above or below
// one another's sight lines, and the exact sign then hides about half of them. So a sample that
// the exact predicate hides behind sample b is still seen where it is seen with its own height
// raised, and b's lowered, by 2^-22 of the sum of the three heights and of the highest one's
// absolute value (a few times the roundings it covers, no more: a wall of a dozen units in the
// last place still hides). Exact on those shifted heights, so every
// implementation takes the same decision.
// Sums, not the largest of the three (compares and selects made the hull tree 25 % slower on
// a city of blocks); the absolute height taken is the highest one's (the base added back: the
// heights are counted from the field's base, either sign, and the highest of three has the
// largest absolute height unless all lie below 0, where the three shifted ones' own absolute
// values still hold it): with each height's own, PoCL no longer vectorised the naive march's loop
// (4x slower).
HFVIS_INLINE float rounding_forgiven(float ha, float hb, float hc, float base) {
  const float highest = ha > hb ? (ha > hc ? ha : hc) : (hb > hc ? hb : hc);
  return 0x1p-22f * (fabs(ha) + fabs(hb) + fabs(hc) + fabs(highest + base));
}

// Whether sample a (farther) is seen from c over sample b within the heights' rounding.
HFVIS_INLINE int seen_within_rounding(float ha, float hb, float hc, float dab, float dbc, float base) {
  const float d = rounding_forgiven(ha, hb, hc, base);
  return chord_side(ha + d, hb - d, hc, dab, dbc) <= 0;
}

// The float filter of chord_side() alone, branch-free: returns whether it decides, and
// then *side is the exact sign. For the naive march, whose straight-line loop PoCL
// vectorises across work-items; rays with an undecided step are marched again with
// chord_side().
HFVIS_INLINE int chord_side_filter(float ha, float hb, float hc, float dab, float dbc, int* side) {
  float dac = dab + dbc;
  float p1 = (hb - hc) * dac;
  float p2 = (ha - hc) * dbc;
  float det = p1 - p2;
  float magnitude = fabs(p1) + fabs(p2);
  int flat = ha == hc && hb == hc;
  *side = flat ? 0 : sign_of(det);
  return flat || (magnitude >= HFVIS_CHORD_FILTER_FLOOR && fabs(det) > HFVIS_CHORD_ERROR_BOUND * magnitude);
}

#endif  // HFVIS_CHORD_SIDE_CL
