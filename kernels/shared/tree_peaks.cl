// tree_peaks.cl: the convex hull tree's occluder-only peaks. The tree samples its lines evenly
// (period / per_period apart), so between two consecutive samples a line crosses grid lines and
// cells: there the bilinear surface can rise above both samples (a one-pixel wall at a column
// crossing, two roofs touching at a corner seen along a diagonal, a street canyon), and a sight
// line over the samples would pass through it. Between two samples the line is cut into pieces,
// each inside one cell, where the surface is a quadratic in the distance along the line; its
// points above the chord of the two samples peak at a piece's end (a crossing) or inside a
// concave piece. The one of these that stands farthest above the chord, where it stands
// strictly above it, enters the tree as an occluder: it hides what lies behind it, but is
// counted as no visible sample and carries no area. Written once in the common subset of
// OpenCL C and C++ (as chord_side.cl): the kernel includes it, and so does
// src/core/tree_peaks.hpp, so the kernel and the scalar tree compute the same peaks bit for bit.
#ifndef HFVIS_TREE_PEAKS_CL
#define HFVIS_TREE_PEAKS_CL

#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline __attribute__((always_inline))
#endif
#else
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline
#endif
#endif

// The surface along one piece of an interval: at t (0 at the interval's far sample, 1 at its
// near one) in [t_far, t_far + span], A + B u + C u^2 with u = (t - t_far) inv_span.
typedef struct {
  float A, B, C, t_far, inv_span;
} TreePieceCurve;

HFVIS_INLINE float tree_curve_at(const TreePieceCurve* c, float t) {
  const float u = (t - c->t_far) * c->inv_span;
  return c->A + (c->B + c->C * u) * u;
}

// One piece of an interval (src/core/lattice_geometry.hpp, TreePiece): the cell fractions at its
// far end (fx, fy) and their change to its near end (dx, dy), where its ends lie in the interval
// (t_far, t_near: 0 at the interval's far sample, 1 at its near one) and 1 / (t_near - t_far).
// The interval's samples span the chord chord_far + chord_rise t. What can occlude more than
// the samples is what rises above that chord; of the piece's points, the candidates are its far
// end where that is a crossing (far_crossing) and, where the piece is concave, the point where
// it stands farthest above the chord (its slope the chord's) where that lies strictly inside.
// A candidate's position is rounded to the line's whole positions (`scale` of them per step,
// at least 2: 2^shift, or on a latitude / longitude grid the step's units of ground length;
// strictly between the samples: integers keep the exact predicate exact) and its height taken there, on
// the piece that holds the rounded position (*prev: the piece before, farther, in the same
// interval), so that a peak is a point of the surface where the tree puts it: a rounded position
// with the unrounded height would tilt sight lines that graze a straight slope through it.
// Keeps in *best_h, *best_offset the candidate that stands farthest above the chord so far
// (*best_excess), and sets *prev to this piece. Corners must be finite: a non-finite one makes
// *best_h NaN, and the interval has no peak.
HFVIS_INLINE void tree_piece_peak(float h00, float h10, float h01, float h11, float fx, float fy, float dx, float dy,
                                  float t_far, float t_near, float inv_span, int far_crossing, float chord_far,
                                  float chord_rise, int scale, TreePieceCurve* prev, float* best_h, int* best_offset,
                                  float* best_excess) {
  const float gx = h10 - h00, gy = h01 - h00, e = (h11 - h01) - gx;
  TreePieceCurve cur;
  cur.A = h00 + gx * fx + gy * fy + e * (fx * fy);
  cur.B = gx * dx + gy * dy + e * (fx * dy + fy * dx);
  cur.C = e * (dx * dy);
  cur.t_far = t_far;
  cur.inv_span = inv_span;
  if (!isfinite(cur.A)) {
    *best_h = NAN;
    *best_excess = INFINITY;  // no later candidate either
    return;
  }
  const float fscale = (float)scale;
  if (far_crossing) {
    int offset = (int)rint(t_far * fscale);
    offset = offset < 1 ? 1 : offset > scale - 1 ? scale - 1 : offset;
    const float t = (float)offset / fscale;
    const float v = t >= t_far ? tree_curve_at(&cur, t) : tree_curve_at(prev, t);
    const float excess = v - (chord_far + chord_rise * t);
    if (excess > *best_excess) {
      *best_excess = excess;
      *best_h = v;
      *best_offset = offset;
    }
  }
  // Along the piece the chord rises by chord_rise (t_near - t_far): the excess's slope at u = 0
  // is B minus that, and it peaks at u = slope / -2C.
  const float span = t_near - t_far;
  const float slope = cur.B - chord_rise * span;
  if (cur.C < 0.0f && slope > 0.0f && slope < -2.0f * cur.C) {
    const float u = slope / (-2.0f * cur.C);
    int lo = (int)ceil(t_far * fscale), hi = (int)floor(t_near * fscale);
    lo = lo < 1 ? 1 : lo;
    hi = hi > scale - 1 ? scale - 1 : hi;
    int offset = (int)rint((t_far + u * span) * fscale);
    offset = offset < lo ? lo : offset > hi ? hi : offset;
    if (lo <= hi) {
      const float t = (float)offset / fscale;
      const float v = tree_curve_at(&cur, t);
      const float excess = v - (chord_far + chord_rise * t);
      if (excess > *best_excess) {
        *best_excess = excess;
        *best_h = v;
        *best_offset = offset;
      }
    }
  }
  *prev = cur;
}

// Whether the peak of height h_peak at `offset` (of the step's `scale` positions) enters the tree: above the chord of its
// interval's two samples (both present) by more than their rounding, 2^-18 of their heights
// (a flat roof's samples come out an ulp or so below its corners, which the peaks' formula
// reproduces exactly: without the margin the roof's own edges would hide its samples), and
// strictly above it, decided exactly (chord_side, which must be defined before this file is
// included). Below or on the chord a peak hides nothing the samples do not.
HFVIS_INLINE int tree_peak_inserted(float h_far, float h_peak, float h_near, int offset, int scale) {
  if (isnan(h_far) || isnan(h_near) || isnan(h_peak)) return 0;
  const float t = (float)offset / (float)scale;
  const float excess = h_peak - (h_far + (h_near - h_far) * t);
  return excess > 0x1p-18f * (fabs(h_far) + fabs(h_near)) &&
         chord_side(h_far, h_peak, h_near, (float)offset, (float)(scale - offset)) > 0;
}

#endif  // HFVIS_TREE_PEAKS_CL
