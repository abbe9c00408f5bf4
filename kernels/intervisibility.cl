// intervisibility.cl: visibility between all points along lattice lines through the pixel
// centres by the convex hull tree (Timonen 2013, Algorithm 1 with segment starts per Eq. 1
// and leaf duplication): the visible count and area of every receiver from its visibility
// horizons, added straight into its pixel, and with HFVIS_WANT_BOUNCE the one-bounce gather
// over the visible runs (Sec. 10.1, alternative 3; bounce.cl); and the naive per-pixel
// visibility march (baseline and oracle).
//
// Visibility (the tie rule, the same everywhere, tests included): on one line, a farther
// sample q is visible from receiver p when no sample strictly between them lies strictly
// above the chord from q to p; equivalently q's slope from p is >= the slope of every
// sample in between. Grazing samples are visible, so on a flat plane everything is. So is a
// hidden sample that the steepest sample between hides only within the heights' rounding, as it
// does every hidden sample between them (seen_within_rounding, forgiven_stretch): so on a
// tilted plane everything is too. Only present samples count (outside the field or without a
// valid corner: absent). Every geometric decision is an exact sign (chord_side()), so the
// tree, the scalar reference and the brute-force oracles agree exactly (see
// src/core/chord_side.hpp for why).
//
// Heights arrive offset and z-scaled (see prepareHeights); NaN = nodata. height_base (both
// kernels' last argument): the height their 0 stands for (PreparedHeights::base), for the rounding
// the tie rule forgives.
//
// Compile-time parameters, besides those of sweep_framework.cl:
//   HFVIS_WANT_COUNT        add the visible counts to count_sum
//   HFVIS_CURVATURE         lower every sample by the Earth's drop (docs/CONVENTIONS.md)
//   HFVIS_WANT_AREA         sum the distances of the visible samples (for the area estimate)
//   HFVIS_WANT_STATS        per-line totals of receivers, horizons, iterations, ...
//   HFVIS_WANT_ENTRY_STATS  per-entry (horizons, iterations, horizon hash) for the tests
//   HFVIS_WANT_BOUNCE       gather exit radiance over the visible samples (bounce.cl)
//   HFVIS_CHANNELS          radiance channels of the bounce, 1..4
//   HFVIS_DEFERRED_WRITES   the tree walk with the old root's level in registers and link
//                           writes only where a link changes (the aim of Algorithm 2); 0 =
//                           Algorithm 1's walk as written, every relink stored at once
//   HFVIS_REPLACEMENT_CHECK the old root's last child is checked first (Sec. 7): when it
//                           fails, every child fails and their own checks are skipped; when
//                           it passes, the old root stays (needs HFVIS_DEFERRED_WRITES)
//   HFVIS_SAFE_ZONE         the safe zone (Algorithm 3): a replaced old root whose children
//                           stay as they are skips the walk (needs HFVIS_REPLACEMENT_CHECK)
//   HFVIS_SAFE_ZONE_STEPS   steps past the receiver that one safe zone covers (a power of 2)
//   HFVIS_ROW_SPACING       the ground spacing differs per row (latitude / longitude grids):
//                           positions along a line are whole units of ground length summed
//                           step by step (row_units), not the steps themselves; not with the
//                           safe zone or the bounce
//   HFVIS_PEAK_PREPASS      intervisibility_peaks computes the samples' heights and the peaks
//                           between them before the sweep, into peak_inputs (not with
//                           per-row spacing or strips); 0 = the sweep computes them itself
//   HFVIS_LANES             lines a prepass work-item takes side by side (shared/lanes.cl: 8 in
//                           a CPU's line-major layout, else 1)
//   HFVIS_PEAK_STEPS        consecutive steps a prepass work-item takes
//   HFVIS_LINE_MAJOR        the scratch is line-major (stride 1: src/core/lattice_geometry.cpp,
//                           chunkLines), known when the program is built, so that the address of
//                           each dependent node load on the tree walk takes no multiply
//   HFVIS_STRIPS            intervisibility_lattice sweeps the receivers of one strip of rows
//                           and resumes each line where the strip before left it (a field in
//                           strips; not with the bounce)
// Every combination builds the same trees (tests/test_intervisibility.cpp): the options
// change the work (iterations t, memory traffic), never a result.
#include "shared/chord_side.cl"
#include "shared/fast_math.cl"
#include "shared/lanes.cl"
#include "shared/sweep_framework.cl"
#include "shared/tree_peaks.cl"

#ifndef HFVIS_WANT_COUNT
#define HFVIS_WANT_COUNT 1
#endif
#ifndef HFVIS_CURVATURE
#define HFVIS_CURVATURE 0
#endif
#ifndef HFVIS_WANT_AREA
#define HFVIS_WANT_AREA 1
#endif
#ifndef HFVIS_WANT_STATS
#define HFVIS_WANT_STATS 1
#endif
#ifndef HFVIS_WANT_ENTRY_STATS
#define HFVIS_WANT_ENTRY_STATS 0
#endif
#ifndef HFVIS_WANT_BOUNCE
#define HFVIS_WANT_BOUNCE 0
#endif
#ifndef HFVIS_CHANNELS
#define HFVIS_CHANNELS 1
#endif
#ifndef HFVIS_DEFERRED_WRITES
#define HFVIS_DEFERRED_WRITES 1
#endif
#ifndef HFVIS_REPLACEMENT_CHECK
#define HFVIS_REPLACEMENT_CHECK 1
#endif
#ifndef HFVIS_SAFE_ZONE
#define HFVIS_SAFE_ZONE 0
#endif
#ifndef HFVIS_SAFE_ZONE_STEPS
#define HFVIS_SAFE_ZONE_STEPS 16
#endif
#ifndef HFVIS_ROW_SPACING
#define HFVIS_ROW_SPACING 0
#endif
#if HFVIS_ROW_SPACING && (HFVIS_SAFE_ZONE || HFVIS_WANT_BOUNCE)
#error "per-row spacing takes neither the safe zone nor the bounce (both assume uniform steps)"
#endif
#ifndef HFVIS_STRIPS
#define HFVIS_STRIPS 0
#endif
#ifndef HFVIS_LINE_MAJOR
#define HFVIS_LINE_MAJOR 0
#endif
// A kernel's scratch stride: its argument, or 1 in the line-major layout.
#define HFVIS_SCRATCH_STRIDE(stride) (HFVIS_LINE_MAJOR ? 1u : (stride))
#ifndef HFVIS_PEAK_PREPASS
#define HFVIS_PEAK_PREPASS 0
#endif
#ifndef HFVIS_PEAK_STEPS
#define HFVIS_PEAK_STEPS 1
#endif
#if HFVIS_PEAK_PREPASS && (HFVIS_ROW_SPACING || HFVIS_STRIPS)
#error "the peaks' prepass takes uniform grids on the whole field (positions from the steps alone)"
#endif
#if HFVIS_STRIPS && HFVIS_WANT_BOUNCE
#error "the bounce reads the radiance of every earlier sample: it needs the whole field"
#endif
// Statistics need every sample's horizons (Table 2 and Section 6's bound count them all);
// otherwise only receivers (pixel centres) read theirs.
#define HFVIS_ALL_HORIZONS (HFVIS_WANT_STATS || HFVIS_WANT_ENTRY_STATS)
#if (HFVIS_REPLACEMENT_CHECK && !HFVIS_DEFERRED_WRITES) || (HFVIS_SAFE_ZONE && !HFVIS_REPLACEMENT_CHECK)
#error "the safe zone needs the replacement check, which works inside the deferred-writes walk"
#endif

#define HFVIS_NONE (-1)
#define HFVIS_CONCAVE 0
#define HFVIS_CONVEX 1
#define HFVIS_LINE_TOTALS 8  // ulongs per line in line_totals

// ---------------------------------------------------------------------------------------
// The convex hull tree sweep.
//
// Tree nodes of a line live in its scratch as int4 (height bits, rank * 2 + leaf flag,
// first child, next sibling), the node of the sample at step k in slot k, links by slot,
// HFVIS_NONE for none. So a line's tree needs one slot per step, and a slot keeps its
// sample's height for good (the visible runs read heights from it). The rank (present
// samples before it) counts run lengths without another read. The leaf flag marks a segment start (Eq. 1: the first
// present sample, and every convex sample after a concave one), whose node is never
// deleted: it starts the convex hull path of its segment.
//
// Leaf duplication (Sec. 5) with twins merged: when a segment start is detected, its own
// node may still be in the tree (the old root kept a child and is the root's last child).
// The paper then adds a leaf copy beside it; the two are siblings with the same geometry,
// so every convexity check treats them alike, forever. Here that node is flagged instead,
// and a leaf is created (in the sample's own, now free, slot) only when the node was
// deleted. Same tree, same horizons, no duplicate horizons, no iterations spent on twins;
// and Sec. 6's bound t <= 2m + n then holds with m = distinct horizons (with separate twins
// it held only counting each twin: 7 lines of blocks_256 at K = 64 exceeded it).
//
// Children are ordered farthest first. The root's children are the receiver's visibility
// horizons, one per segment start j: the farthest sample of maximal slope from the
// receiver among samples j .. receiver - 1.

#define HFVIS_LEAF 1  // bit 0 of node.y

// Tree slots. Between consecutive samples, the surface's highest point above their chord
// (kernels/shared/tree_peaks.cl) enters the tree as an occluder alone, so a line has two slots
// per step: 2 s for the peak between steps s - 1 and s (most are never inserted), 2 s + 1 for
// step s's sample. Positions are then fixed point: position_shift bits below the step, or with
// per-row spacing the step's whole units of ground length. SAMPLE_OF: the step of a slot's
// sample or peak; SLOT_OF: a step's sample.
#define SAMPLE_OF(slot) ((slot) >> 1)
#define IS_SAMPLE(slot) ((slot)&1)
#define SLOT_OF(step) (2 * (step) + 1)
#define PEAK_SLOT(step) (2 * (step))

// One piece of an interval between two samples inside one cell (src/core/lattice_geometry.hpp,
// TreePiece): ten 4-byte members, read field by field.
typedef struct {
  int ox, oy;
  float fx, fy, dx, dy, t_far, t_near, inv_span;
  int far_crossing;
} TreePiece;

// The position of step k's sample (its positions[] from the line's first entry): the step in
// units of 2^-shift step, or with per-row spacing its units (whole
// numbers below 2^24: exact in a float, and so are their differences).
HFVIS_INLINE float sample_position(__global const int2* positions, uint stride, int shift, int k) {
#if HFVIS_ROW_SPACING
  return (float)positions[(uint)k * stride].x;
#else
  return (float)(k << shift);
#endif
}

// The position of the node in `slot`: a peak's node keeps its position in place of a rank
// (node.y = position * 2 + leaf flag).
HFVIS_INLINE float node_position(__global const int2* positions, uint stride, int shift, int slot, int4 node) {
  if (!IS_SAMPLE(slot)) return (float)(node.y >> 1);
  return sample_position(positions, stride, shift, SAMPLE_OF(slot));
}

// The rank of the node in `slot` (present samples before it): a peak's is that of the sample
// after it, which shares its rank.
HFVIS_INLINE int node_rank(__global const int4* tree, uint stride, int slot, int4 node) {
  if (!IS_SAMPLE(slot)) return tree[(uint)(slot | 1) * stride].y >> 1;
  return node.y >> 1;
}

// Whether sample x at position px (farther than the next horizon n) is seen over n from
// receiver r.
inline int seen_over(float hx, float px, float hn, float pn, float hr, float pr) {
  return chord_side(hx, hn, hr, pn - px, pr - pn) <= 0;
}

// The visible nodes between horizon `start` and the next horizon `next` (slots) form a
// prefix (every start of a visible run is a horizon), and are exactly those seen over `next`;
// so do the samples among them, which are all a run counts (peaks are occluders alone), so
// only samples are searched. Returns the slot that ends the prefix: the first present sample
// hidden behind `next`, or `next`. Heights are read from the tree slots (a slot keeps its
// sample's height for good; absent samples' slots hold NaN). Without absent samples in
// between, galloping then bisection (O(log run)); otherwise a scan.
HFVIS_INLINE int run_end(__global const int4* tree, __global const int2* positions, uint stride, int shift, int start,
                   int next, float h_next, float p_next, float p_receiver, float h_receiver, int holes) {
  int lo = SAMPLE_OF(start) - (IS_SAMPLE(start) ? 0 : 1);  // the last sample known visible
  const int last = SAMPLE_OF(next);
  if (!holes) {
    int hi = last, jump = 1;
    while (lo + jump < hi) {
      int x = lo + jump;
      if (seen_over(as_float(tree[(uint)SLOT_OF(x) * stride].x), sample_position(positions, stride, shift, x), h_next,
                    p_next, h_receiver, p_receiver)) {
        lo = x;
        jump *= 2;
      } else {
        hi = x;
        break;
      }
    }
    while (hi - lo > 1) {
      int mid = lo + (hi - lo) / 2;
      if (seen_over(as_float(tree[(uint)SLOT_OF(mid) * stride].x), sample_position(positions, stride, shift, mid),
                    h_next, p_next, h_receiver, p_receiver))
        lo = mid;
      else
        hi = mid;
    }
    return hi == last ? next : SLOT_OF(hi);
  }
  for (int x = lo + 1; x < last; ++x) {
    float hx = as_float(tree[(uint)SLOT_OF(x) * stride].x);
    if (!isnan(hx) &&
        !seen_over(hx, sample_position(positions, stride, shift, x), h_next, p_next, h_receiver, p_receiver))
      return SLOT_OF(x);
  }
  return next;
}

// The stretch of hidden samples that `horizon` (slot; height h_h, position p_h) hides only
// within the heights' rounding (chord_side.cl): going farther out from it, down to step `last_step`
// and no farther than the line's first present sample, every present sample seen over it within
// the rounding, up to the first that is not. Such samples are seen (the tie rule: on a tilted
// plane every sample is, though the rounding tips about half of them below the sight line of a
// nearer one). Returns the step of the farthest, or -1 where there is none. Absent samples
// neither count nor end the stretch.
HFVIS_INLINE int forgiven_stretch(__global const int4* tree, __global const int2* positions, uint stride,
                                  int shift, int last_step, int horizon, float h_h, float p_h,
                                  float p_receiver, float h_receiver, float height_base) {
  int farthest = -1;
  for (int x = SAMPLE_OF(horizon) - 1; x >= last_step; --x) {
    const int4 node = tree[(uint)SLOT_OF(x) * stride];
    const float hx = as_float(node.x);
    if (isnan(hx)) continue;
    const float px = sample_position(positions, stride, shift, x);
    if (!seen_within_rounding(hx, h_h, h_receiver, p_h - px, p_receiver - p_h, height_base)) break;
    farthest = x;
    if ((node.y >> 1) == 0) break;  // the line's first present sample
  }
  return farthest;
}

#if HFVIS_WANT_BOUNCE
#include "bounce.cl"
#endif

// The root's new child list while Algorithm 1 builds it: appending x links the last child
// to x. `tail_next` is what the last child's `next` link holds in memory, so that with
// deferred writes a link that is already right (a run of siblings that join the root in
// their old order, the common case) is not written again.
typedef struct {
  int head, tail, tail_next;
  float tail_h, tail_p;  // the last child's height and position (the replacement check reads them)
} RootList;

HFVIS_INLINE void root_append(__global int4* tree, uint stride, RootList* list, int x, float hx, float px,
                              int x_next_in_memory) {
  if (list->tail == HFVIS_NONE)
    list->head = x;
  else if (!HFVIS_DEFERRED_WRITES || list->tail_next != x)
    tree[(uint)list->tail * stride].w = x;
  list->tail = x;
  list->tail_next = x_next_in_memory;
  list->tail_h = hx;
  list->tail_p = px;
}

// Algorithm 1 below node `top` (the old root, or with deferred writes a child of it already
// detached): every child that fails the convexity check (child -> parent -> new root) joins
// the root before its parent, its own children are checked in turn, and a parent left
// without children is deleted (leaves never are). A post-order walk that appends the
// root's new children in order; its stack is threaded through the `next` links of the
// nodes on it (a detached child's sibling link is free until it is appended), and `top`
// returns to the caller. Returns the convexity checks made.
HFVIS_INLINE uint hull_tree_walk(__global int4* tree, __global const int2* positions, uint stride, int shift, int top,
                                 int4 node, float h, float p, RootList* list) {
  uint t = 0;
  int cur = top;
  for (;;) {
    const int c = node.z;
    if (c != HFVIS_NONE) {
      int4 child = tree[(uint)c * stride];
      ++t;
      // Convex when the parent lies strictly above the chord from the child to the root.
      const float p_cur = node_position(positions, stride, shift, cur, node);
      const int side = chord_side(as_float(child.x), as_float(node.x), h,
                                  p_cur - node_position(positions, stride, shift, c, child), p - p_cur);
      if (side <= 0) {
        node.z = child.w;  // the next child becomes the first
        tree[(uint)cur * stride] = node;
        child.w = cur;  // back link to resume the parent
        tree[(uint)c * stride] = child;
        cur = c;
        node = child;
        continue;
      }
    }
    // A node keeps its `next` in memory: the back link on the walk, the sibling for `top`.
    if (c != HFVIS_NONE || (node.y & HFVIS_LEAF))
      root_append(tree, stride, list, cur, as_float(node.x), node_position(positions, stride, shift, cur, node),
                  node.w);
    if (cur == top) break;
    cur = node.w;
    node = tree[(uint)cur * stride];
  }
  return t;
}

#if HFVIS_SAFE_ZONE
// The safe zone (Sec. 7, Figure 9, Algorithm 3): a new root replaces the old one without
// other change when every child of the old root fails its convexity check (it suffices that
// the last one fails: the children's slopes from the root fall toward it) and every first
// grandchild passes (c stays above the chord from its first child g to the new sample: the
// new sample lies strictly below the line g -> c). Below the lowest of those lines at two
// boundaries b1 and b2, the chord between the two lowest points bounds a zone where the
// second holds for every child (the lowest of lines is concave). The zone holds while the
// children and their first children stay: until the walk runs, or the receiver passes b2.
typedef struct {
  float first, last;  // positions it covers, b1 .. b2 = b1 + HFVIS_SAFE_ZONE_STEPS steps
  float z1, z2;       // bound at b1 and b2
  float margin;       // covers the rounding of the bound: inside only below bound - margin
} SafeZone;

// One root child at position c, height hc, with first child at g, height hg: lowers the bound.
HFVIS_INLINE void safe_zone_add(SafeZone* z, float hc, float c, float hg, float g) {
  const float slope = (hc - hg) / (c - g);
  const float at1 = hc + slope * (z->first - c);
  const float at2 = hc + slope * (z->last - c);
  z->z1 = hf_min(z->z1, at1);
  z->z2 = hf_min(z->z2, at2);
  // |rounding| of at1, at2 and of the interpolation stays within a few ulps of this.
  z->margin = hf_max(z->margin, fabs(hc) + fabs(slope) * (z->last - c));
}

// From just past the receiver at position p (a peak may follow it within the step) over
// HFVIS_SAFE_ZONE_STEPS steps of `unit` (2^position_shift) positions.
HFVIS_INLINE void safe_zone_begin(SafeZone* z, float p, float unit) {
  z->first = p + 1.0f;
  z->last = z->first + unit * (float)HFVIS_SAFE_ZONE_STEPS;
  z->z1 = z->z2 = FLT_MAX;  // no first grandchild: nothing to stay convex
  z->margin = 0.0f;
}

// Relative to the magnitudes, plus an absolute floor for subnormal heights (whose
// rounding is absolute, up to 2^-149 per operation).
HFVIS_INLINE void safe_zone_end(SafeZone* z) { z->margin = z->margin * 0x1p-16f + 0x1p-100f; }

// Whether a node at position p, height h is inside (the zone must not have expired).
HFVIS_INLINE int safe_zone_inside(const SafeZone* z, float p, float h) {
  const float bound = z->z1 + (z->z2 - z->z1) * ((p - z->first) / (z->last - z->first));
  return p <= z->last && h < bound - z->margin;
}
#endif

// The height of sample q of period i of a line, whose receiver is (col, row) (heights hold rows
// from row0 on): absent (NaN) where only the first period reaches, outside the field; with
// HFVIS_CURVATURE lowered by the Earth's drop at d_sample steps from the line's start.
HFVIS_INLINE float tree_sample_height(__global const float* heights, int width, int height, int row0,
                                      __global const LatticeSample* samples, int q, int i, int col, int row,
                                      float drop, float d_sample) {
  __global const LatticeSample* s = samples + q;
  const int x0 = col + s->ox, y0 = row + s->oy, ex = s->ex, ey = s->ey;
  float h_sample = NAN;
  if (i > 0 || (x0 >= 0 && x0 + ex <= width - 1 && y0 >= 0 && y0 + ey <= height - 1)) {
    const uint at = (uint)((y0 - row0) * width + x0);
    // The receiver is its pixel's height as it is (1 h + 0 h would make an infinity NaN).
    h_sample = ex + ey == 0 ? heights[at]
                            : lattice_height(heights, at, (uint)ex, (uint)(ey * width), s->w00, s->w10, s->w01, s->w11);
  }
#if HFVIS_CURVATURE
  // The Earth's drop from any receiver p, drop (p - step)^2 (drop per step squared), differs
  // from drop step^2 by a term linear in step: every slope seen from p shifts alike, so
  // every visibility decision (and the tree) is that of the heights lowered by drop step^2
  // (positions with per-row spacing).
  h_sample = h_sample - drop * d_sample * d_sample;
#endif
  return h_sample;
}

#if HFVIS_CURVATURE
// The Earth's drop at an interval's two samples (position_far, in 2^-shift steps, and d_sample
// steps from the line's start), which its peak's candidates and chord add back: the candidates
// are points of the surface before the drop (theirs comes after), and so is the chord they are
// measured against, else the drop's growth along the interval (2 drop step per step) would
// favour the near end's candidates far out on a line.
HFVIS_INLINE void tree_chord_lifts(float drop, float inv_scale, float d_sample, int position_far, float* far_lift,
                                   float* near_lift) {
  const float d_far = (float)position_far * inv_scale;
  *far_lift = drop * d_far * d_far;
  *near_lift = drop * d_sample * d_sample;
}
#endif

// The peak between step - 1 (height h_sample_prev) and step (h_sample, sample q of period i,
// its receiver at (col, row)): of the interval's crossings and concave pieces, the point that
// stands farthest above the chord of its two samples, where it stands strictly above it; NaN
// where there is none. Its position (position_far + its offset among the step's step_scale
// positions) in *peak_position.
HFVIS_INLINE float tree_interval_peak(__global const float* heights, int width, int height, int row0,
                                      __global const TreePiece* pieces, __global const int* interval_first, int q,
                                      int i, int col, int row, int step, float h_sample_prev, float h_sample,
                                      float drop, float inv_scale, float d_sample, int position_far, int step_scale,
                                      int* peak_position) {
  if (!(step > 0 && step_scale > 1 && !isnan(h_sample_prev) && !isnan(h_sample))) return NAN;
  float best_h = -INFINITY, best_excess = 0.0f;
  int offset = 0;
  TreePieceCurve curve;  // the piece before (set by the first piece, which has no crossing)
  float chord_far = h_sample_prev, rise = h_sample - h_sample_prev;
#if HFVIS_CURVATURE
  float far_lift, near_lift;
  tree_chord_lifts(drop, inv_scale, d_sample, position_far, &far_lift, &near_lift);
  chord_far = h_sample_prev + far_lift;
  rise = (h_sample + near_lift) - chord_far;
#endif
  for (int k = interval_first[q]; k < interval_first[q + 1]; ++k) {
    __global const TreePiece* g = pieces + k;
    const int px = col + g->ox, py = row + g->oy;
    if (i == 0 && (px < 0 || px + 1 > width - 1 || py < 0 || py + 1 > height - 1)) return NAN;
    const uint at = (uint)((py - row0) * width + px);
    tree_piece_peak(heights[at], heights[at + 1], heights[at + (uint)width], heights[at + (uint)width + 1], g->fx,
                    g->fy, g->dx, g->dy, g->t_far, g->t_near, g->inv_span, g->far_crossing, chord_far, rise,
                    step_scale, &curve, &best_h, &offset, &best_excess);
  }
  if (!(best_h > -INFINITY)) return NAN;  // (NaN: a corner was)
  *peak_position = position_far + offset;
#if HFVIS_CURVATURE
  const float d_peak = (float)*peak_position * inv_scale;
  best_h = best_h - drop * d_peak * d_peak;
#endif
  return tree_peak_inserted(h_sample_prev, best_h, h_sample, offset, step_scale) ? best_h : NAN;
}

#if HFVIS_PEAK_PREPASS
// The exact sign of chord_side(ha, hb, hc, dab, dbc) > 0 in every lane: the float filter side
// by side, the exact expansion lane by lane where the filter does not decide (rare). `want`:
// the lanes whose answer is used (others may hold anything).
HFVIS_INLINE lane_int chord_above_lanes(lane_float ha, lane_float hb, lane_float hc, lane_float dab, lane_float dbc,
                                        lane_int want) {
  const lane_int flat = (ha == hc) & (hb == hc);
  const lane_float dac = dab + dbc;
  const lane_float p1 = (hb - hc) * dac, p2 = (ha - hc) * dbc;
  const lane_float det = p1 - p2, magnitude = fabs(p1) + fabs(p2);
  const lane_int decided = (magnitude >= HFVIS_CHORD_FILTER_FLOOR) & (fabs(det) > HFVIS_CHORD_ERROR_BOUND * magnitude);
  lane_int above = (flat == 0) & decided & (det > 0.0f);
  const lane_int undecided = want & (flat == 0) & (decided == 0);
  if (ANY_LANE(undecided)) {
    for (int l = 0; l < HFVIS_LANES; ++l) {
      if (ILANE(undecided, l))
        ILANE(above, l) = exact_chord_side(LANE(ha, l), LANE(hb, l), LANE(hc, l), LANE(dab, l), LANE(dbc, l),
                                           LANE(dac, l)) > 0
                              ? ILANE(undecided, l)  // (-1 in a vector lane, 1 in a scalar: a mask)
                              : 0;
    }
  }
  return above;
}

// tree_interval_peak (and tree_piece_peak, tree_peak_inserted) for HFVIS_LANES lines side by side
// at one step, as the prepass runs them: the lines share the step, so its pieces, their ends and
// the positions a crossing rounds to are the same in every lane; only the corners' heights differ.
// Every lane takes the scalar functions' operations in their order, so each lane's peak is theirs
// bit for bit (PeakPrepassMatchesTheReference); their branches become selects. Lanes whose
// samples are absent (h_far or h_near NaN, lines shorter than the step) get NaN.
HFVIS_INLINE lane_float tree_interval_peak_lanes(__global const float* heights, int width, int height,
                                                 __global const TreePiece* pieces, __global const int* interval_first,
                                                 int q, int i, lane_int col, lane_int row, int step, lane_float h_far,
                                                 lane_float h_near, float drop, float inv_scale, float d_sample,
                                                 int position_far, int step_scale, lane_int* peak_position) {
  *peak_position = (lane_int)(0);
  if (!(step > 0 && step_scale > 1)) return (lane_float)(NAN);
  const float fscale = (float)step_scale;
  lane_int live = (isnan(h_far) == 0) & (isnan(h_near) == 0);
  lane_float best_h = (lane_float)(-INFINITY), best_excess = (lane_float)(0.0f);
  lane_int offset = (lane_int)(0);
  lane_float prev_A = (lane_float)(0.0f), prev_B = prev_A, prev_C = prev_A;  // the piece before's curve
  float prev_t_far = 0.0f, prev_inv_span = 0.0f;
  lane_float chord_far = h_far, rise = h_near - h_far;
#if HFVIS_CURVATURE
  float far_lift, near_lift;
  tree_chord_lifts(drop, inv_scale, d_sample, position_far, &far_lift, &near_lift);
  chord_far = h_far + far_lift;
  rise = (h_near + near_lift) - chord_far;
#endif
  for (int k = interval_first[q]; k < interval_first[q + 1]; ++k) {
    __global const TreePiece* g = pieces + k;
    const float fx = g->fx, fy = g->fy, dx = g->dx, dy = g->dy, t_far = g->t_far, t_near = g->t_near,
                inv_span = g->inv_span;
    const lane_int px = col + g->ox, py = row + g->oy;
    if (i == 0)  // outside the field: no peak
      live = live & (px >= 0) & (px + 1 <= width - 1) & (py >= 0) & (py + 1 <= height - 1);
    const lane_int at = py * width + px;
    // A lane's corner, read where the lane is live (its cell may lie outside the field otherwise).
#define HFVIS_CORNER(l, offset) (ILANE(live, l) ? heights[(uint)ILANE(at, l) + (offset)] : 0.0f)
#define HFVIS_H00(l) HFVIS_CORNER(l, 0u)
#define HFVIS_H10(l) HFVIS_CORNER(l, 1u)
#define HFVIS_H01(l) HFVIS_CORNER(l, (uint)width)
#define HFVIS_H11(l) HFVIS_CORNER(l, (uint)width + 1u)
    const lane_float h00 = LANES_FROM(HFVIS_H00), h10 = LANES_FROM(HFVIS_H10), h01 = LANES_FROM(HFVIS_H01),
                     h11 = LANES_FROM(HFVIS_H11);
#undef HFVIS_CORNER
#undef HFVIS_H00
#undef HFVIS_H10
#undef HFVIS_H01
#undef HFVIS_H11
    const lane_float gx = h10 - h00, gy = h01 - h00, e = (h11 - h01) - gx;
    const lane_float A = h00 + gx * fx + gy * fy + e * (fx * fy);
    const lane_float B = gx * dx + gy * dy + e * (fx * dy + fy * dx);
    const lane_float C = e * (dx * dy);
    // A non-finite corner: the interval has no peak (tree_piece_peak's NaN, no later candidate).
    const lane_int infinite = isfinite(A) == 0;
    best_h = select(best_h, (lane_float)(NAN), infinite);
    best_excess = select(best_excess, (lane_float)(INFINITY), infinite);
    if (g->far_crossing) {
      int off = (int)rint(t_far * fscale);
      off = off < 1 ? 1 : off > step_scale - 1 ? step_scale - 1 : off;
      const float t = (float)off / fscale;
      lane_float v;
      if (t >= t_far) {
        const float u = (t - t_far) * inv_span;
        v = A + (B + C * u) * u;
      } else {
        const float u = (t - prev_t_far) * prev_inv_span;
        v = prev_A + (prev_B + prev_C * u) * u;
      }
      const lane_float excess = v - (chord_far + rise * t);
      const lane_int better = excess > best_excess;
      best_excess = select(best_excess, excess, better);
      best_h = select(best_h, v, better);
      offset = select(offset, (lane_int)(off), better);
    }
    const float span = t_near - t_far;
    const lane_float slope = B - rise * span;
    int lo = (int)ceil(t_far * fscale), hi = (int)floor(t_near * fscale);
    lo = lo < 1 ? 1 : lo;
    hi = hi > step_scale - 1 ? step_scale - 1 : hi;
    const lane_int concave = (C < 0.0f) & (slope > 0.0f) & (slope < -2.0f * C);
    if (lo <= hi && ANY_LANE(concave)) {
      const lane_float u = slope / (-2.0f * C);
      // Other lanes' u may be anything: their position is replaced before it becomes an integer.
      const lane_float at_vertex = select((lane_float)((float)lo), rint((t_far + u * span) * fscale), concave);
      lane_int off = LANE_INT(at_vertex);
      off = select(off, (lane_int)(lo), off < lo);
      off = select(off, (lane_int)(hi), off > hi);
      const lane_float t = LANE_FLOAT(off) / fscale;
      const lane_float w = (t - t_far) * inv_span;
      const lane_float v = A + (B + C * w) * w;
      const lane_float excess = v - (chord_far + rise * t);
      const lane_int better = concave & (excess > best_excess);
      best_excess = select(best_excess, excess, better);
      best_h = select(best_h, v, better);
      offset = select(offset, off, better);
    }
    prev_A = A;
    prev_B = B;
    prev_C = C;
    prev_t_far = t_far;
    prev_inv_span = inv_span;
  }
  live = live & (best_h > -INFINITY);  // (NaN: a corner was)
  *peak_position = position_far + offset;
#if HFVIS_CURVATURE
  const lane_float d_peak = LANE_FLOAT(*peak_position) * inv_scale;
  best_h = best_h - drop * d_peak * d_peak;
#endif
  // tree_peak_inserted
  const lane_float t = LANE_FLOAT(offset) / (float)step_scale;
  const lane_float excess = best_h - (h_far + (h_near - h_far) * t);
  live = live & (isnan(best_h) == 0) & (excess > 0x1p-18f * (fabs(h_far) + fabs(h_near)));
  live = live & chord_above_lanes(h_far, best_h, h_near, LANE_FLOAT(offset), LANE_FLOAT(step_scale - offset), live);
  return select((lane_float)(NAN), best_h, live);
}

// The samples' heights and the peaks between them, ahead of the sweep (HFVIS_PEAK_PREPASS):
// a work-item takes HFVIS_PEAK_STEPS consecutive steps of HFVIS_LANES lines (lines j0 .. j0 +
// HFVIS_LANES - 1, side by side in its SIMD lanes on a CPU), none waiting on another, where the
// sweep's one work-item per line would evaluate them between its dependent tree walks. Step s of line j (its sample q of period
// i, as intervisibility_lattice numbers them) writes its sample's height into
// peak_inputs[SLOT_OF(s)] (x, a float's bits) and its peak (the height's bits, NaN for none; the
// position) into peak_inputs[PEAK_SLOT(s)], as integers (a position's bits as a float would be a
// denormal, which a device without denormals may flush to zero in a move), laid out as the tree's
// slots (8 bytes a slot where a node takes 16: the pass costs memory traffic, which decides its
// gain on a CPU). Arguments as intervisibility_lattice's (uniform grids only: no per-row spacing,
// no strips).
// The steps of a work-item follow each other, so that each sample's height is computed once (the
// next step's interval starts at it). Where the peak is NaN the position is unspecified.
// Global size: (lines / HFVIS_LANES, steps of the longest line / HFVIS_PEAK_STEPS), each rounded up
// to a whole number, then to the local size.
__kernel void intervisibility_peaks(__global const float* heights, int width, int height, __global const int4* lines,
                                    int n_lines, __global const LatticeSample* samples, int n_samples, int a, int b,
                                    float drop, __global const TreePiece* pieces, __global const int* interval_first,
                                    int position_shift, __global int2* peak_inputs, uint stride) {
  const int j0 = get_global_id(0) * HFVIS_LANES, first_step = get_global_id(1) * HFVIS_PEAK_STEPS;
  if (j0 >= n_lines) return;
  stride = HFVIS_SCRATCH_STRIDE(stride);
  const float inv_scale = 1.0f / (float)(1 << position_shift);
  const int step_scale = 1 << position_shift;
  int4 line[HFVIS_LANES];
  for (int l = 0; l < HFVIS_LANES; ++l) line[l] = lines[j0 + l < n_lines ? j0 + l : j0];
  // Each lane's line: its steps (0 past the last line), its first receiver.
#define HFVIS_STEPS(l) (j0 + (l) < n_lines ? line[l].z * n_samples : 0)
#define HFVIS_COL0(l) (line[l].x)
#define HFVIS_ROW0(l) (line[l].y)
  const lane_int line_steps = ILANES_FROM(HFVIS_STEPS), col0 = ILANES_FROM(HFVIS_COL0), row0 = ILANES_FROM(HFVIS_ROW0);
  // The sample of step `step` (period i, sample q) in each lane on its line, NaN past its end.
#define HFVIS_SAMPLE(l)                                                                                              \
  (ILANE(on_line, l) ? tree_sample_height(heights, width, height, 0, samples, q, i, ILANE(col0, l) - i * a,          \
                                          ILANE(row0, l) - i * b, drop, d_sample)                                    \
                     : NAN)
  // The sample before the first step (the previous one of its period, or the receiver before);
  // then each step's sample is the next one's h_prev.
  lane_float h_prev = (lane_float)(NAN);
  if (first_step > 0) {
    const int step = first_step - 1, i = step / n_samples, q = step - i * n_samples;
    const float d_sample = (float)(step << position_shift) * inv_scale;
    const lane_int on_line = line_steps > step;
    h_prev = LANES_FROM(HFVIS_SAMPLE);
  }
  for (int step = first_step; step < first_step + HFVIS_PEAK_STEPS; ++step) {
    const int i = step / n_samples, q = step - i * n_samples;
    const float d_sample = (float)(step << position_shift) * inv_scale;
    const lane_int on_line = line_steps > step;
    if (!ANY_LANE(on_line)) return;  // (lines only end: later steps are past them too)
    const lane_float h_sample = LANES_FROM(HFVIS_SAMPLE);
    const lane_int col = col0 - i * a, row = row0 - i * b;
    lane_int peak_position;
    const lane_float h_peak = tree_interval_peak_lanes(heights, width, height, pieces, interval_first, q, i, col, row,
                                                       step, h_prev, h_sample, drop, inv_scale, d_sample,
                                                       (step - 1) << position_shift, step_scale, &peak_position);
    for (int l = 0; l < HFVIS_LANES; ++l) {
      if (!ILANE(on_line, l)) continue;
      __global int2* inputs = peak_inputs + (uint)line[l].w;
      inputs[(uint)SLOT_OF(step) * stride] = (int2)(as_int(LANE(h_sample, l)), 0);
      inputs[(uint)PEAK_SLOT(step) * stride] = (int2)(as_int(LANE(h_peak, l)), ILANE(peak_position, l));
    }
    h_prev = h_sample;
  }
#undef HFVIS_STEPS
#undef HFVIS_COL0
#undef HFVIS_ROW0
#undef HFVIS_SAMPLE
}
#endif

// What a line's sweep keeps in registers between its samples, saved at the end of a strip and
// restored at the start of the next one (HFVIS_STRIPS): the tree itself stays in the scratch.
typedef struct {
  ulong step_sum, weighted_sum, total_m, total_t, total_naive, total_visible;
  int rank, root, prev, prev2, class_last, head, tail, position;
  uint unit_sum, zone_skips;
  int zone_valid, y_prev, total_peaks;
  float h_prev, h_prev2, p_prev, p_prev2, tail_h, tail_p, h_sample_prev, zone_first, zone_last, zone_z1, zone_z2,
      zone_margin;
} TreeLineState;
// The host allocates kTreeLineStateBytes (src/core/hull_tree_device.hpp) per line.
typedef char tree_line_state_is_152_bytes[sizeof(TreeLineState) == 152 ? 1 : -1];
// The registers saved and restored, X(register, its TreeLineState field), those of per-row
// spacing and of the safe zone where compiled in.
#if HFVIS_ROW_SPACING
#define HFVIS_ROW_REGISTERS(X) X(weighted_sum, weighted_sum) X(position, position) X(unit_sum, unit_sum)
#else
#define HFVIS_ROW_REGISTERS(X)
#endif
#if HFVIS_SAFE_ZONE
#define HFVIS_ZONE_REGISTERS(X)                                                                    \
  X(zone_valid, zone_valid) X(zone.first, zone_first) X(zone.last, zone_last) X(zone.z1, zone_z1) \
  X(zone.z2, zone_z2) X(zone.margin, zone_margin)
#else
#define HFVIS_ZONE_REGISTERS(X)
#endif
#define HFVIS_LINE_REGISTERS(X)                                                                       \
  X(step_sum, step_sum) X(total_m, total_m) X(total_t, total_t) X(total_naive, total_naive)            \
  X(total_visible, total_visible) X(rank, rank) X(root, root) X(prev, prev) X(prev2, prev2)            \
  X(class_last, class_last) X(head, head) X(tail, tail) X(zone_skips, zone_skips) X(h_prev, h_prev)    \
  X(h_prev2, h_prev2) X(p_prev, p_prev) X(p_prev2, p_prev2) X(tail_h, tail_h) X(tail_p, tail_p)        \
  X(y_prev, y_prev) X(h_sample_prev, h_sample_prev) X(total_peaks, total_peaks) HFVIS_ROW_REGISTERS(X) \
  HFVIS_ZONE_REGISTERS(X)
#define HFVIS_RESTORE(reg, field) reg = st.field;
#define HFVIS_SAVE(reg, field) st.field = reg;

// The sweep of one direction (a, b) on lattice lines (src/core/lattice_geometry.hpp): every pixel
// centre lies on exactly one line of the direction, so every receiver is a sample of the
// line through its own centre, at its own height, and its tree gives the visible samples
// of its own ray. One work-item per line, from its far end toward -(a, b). Line j's
// farthest receiver is lines[j] = (col, row, receivers, scratch); receiver i sits at
// (col - i a, row - i b). Per receiver, the n_samples samples of its period come farthest
// first (samples[0 .. n_samples - 2], equally spaced between the previous receiver and
// this one), then the receiver itself (tau 0, weight 1 on its own pixel): steps along the
// line are uniform, step s of a line is its s-th sample. Only the first period can reach
// outside the field; samples outside it or without a valid corner are absent. Every sample
// is inserted into the tree; only receivers read their visible runs (step 3).
//
// Scratch (stride 1 in the line-major layout, the launch's line count in the step-major
// one), entry s of line j at lines[j].w + s * stride:
//   trees[]   the tree node of step s (height, rank * 2 + leaf, first child, next sibling);
//             an absent sample's slot holds a NaN height,
//   prefix[]  the sum of the steps of the present samples before step s (for the area
//             across holes), if AREA and HAS_NODATA; with ROW_SPACING (and AREA) the sum
//             of position * units over them,
//   positions[] with ROW_SPACING: (position of step s in units, the sum of the units of the
//             present samples before it). Per receiver row r, the period ending at the
//             receiver has steps of row_units[r] units each, and row_factors[r] replaces
//             (count_factor, area_factor) (the area's per unit squared); drop is per unit
//             squared and max_steps counts units. The distance sum is then that of
//             (receiver position - position) * ring units over the counted samples (the
//             units of each one's step toward the receiver: the width of its ring),
//   visible[], entry_stats[] per-step (count, distance sum) and (horizons m, iterations t,
//             horizon hash, walk skipped), if ENTRY_STATS.
// Outputs, added at each receiver's pixel (one launch per direction, and each pixel is a
// receiver of one line of it, so no atomics; NaN at nodata receivers):
//   count_sum[]   count_factor * visible samples (within max_steps of the receiver),
//   area_sum[]    area_factor * their distance sum in steps, if AREA,
//   irradiance[]  the gathered irradiance, HFVIS_CHANNELS planes, if BOUNCE (reading
//                 `radiance`, HFVIS_CHANNELS planes, and `normals`, three planes x, y, z),
//   line_totals[(first_line + j) * 8 + ...] (present samples, sum m, sum t, naive
//                 iterations, visible samples, walks skipped by the safe zone, 0, 0), if STATS.
// With statistics (STATS or ENTRY_STATS) every sample reads its visible runs, as Timonen
// 2013's Table 2 counts them per line sample; outputs still come from the receivers only.
// Preconditions: a line has fewer than 2^24 steps (checked by the host). Memory safety does
// not rest on the predicate: leaves are never deleted and a node only when childless, so
// every subtree holds a leaf and the root never loses all children; a slot is reused only
// for the deleted old root. Global size: the launch's lines rounded up to the local size.
// With HFVIS_STRIPS a launch sweeps line j's receivers strip_receivers[j].x .. .y - 1 (those
// in one strip of rows; the strips go in the order the lines run through them), resuming from
// states[j] when it does not start at receiver 0 and saving it at the end; heights holds rows
// from row0 on (the strip and a halo of the rows its periods reach), count_sum and area_sum
// rows from out_row0 on, and line_totals the totals so far.
__kernel void intervisibility_lattice(
    __global const float* heights, int width, int height, __global const int4* lines, int n_lines,
    __global const LatticeSample* samples, int n_samples, int a, int b, float count_factor, float area_factor,
    float drop, int max_steps, __global const int* row_units, __global const float2* row_factors,
    __global const TreePiece* pieces, __global const int* interval_first, int position_shift,
    __global const int2* peak_inputs, __global int4* trees, __global ulong* prefix, __global int2* positions,
    uint stride, __global float2* visible, __global uint4* entry_stats, __global ulong* line_totals,
    int first_line, __global float* count_sum, __global float* area_sum, __global const float* radiance,
    __global const float* normals, float cos_azimuth, float sin_azimuth, float step_ground, float half_sector,
    float wedge, __global float* irradiance, int row0, int out_row0, __global const int2* strip_receivers,
    __global TreeLineState* states, float height_base) {
  const int j = get_global_id(0);
  if (j >= n_lines) return;
  stride = HFVIS_SCRATCH_STRIDE(stride);
  const int4 line = lines[j];
#if HFVIS_STRIPS
  const int2 strip = strip_receivers[j];
  if (strip.x >= strip.y) return;  // no receiver of this line in the strip
  const int i_begin = strip.x, i_end = strip.y;
#else
  const int i_begin = 0, i_end = line.z;
  row0 = out_row0 = 0;
#endif
  const uint base = (uint)line.w;
  __global int4* tree = trees + base;
  __global int2* line_positions = positions + base;
  __global const int2* line_peak_inputs = peak_inputs + base;  // (HFVIS_PEAK_PREPASS)
  const uint plane = (uint)(width * height);
  // Positions are in units of 2^-position_shift step: back to steps (exactly) for the drop.
  const float inv_scale = 1.0f / (float)(1 << position_shift);

  int rank = 0;        // present samples before `step`
  ulong step_sum = 0;  // the sum of their steps
  int root = HFVIS_NONE;
  int prev = HFVIS_NONE, prev2 = HFVIS_NONE;  // the two latest present nodes (slots)
  float h_prev = 0.0f, h_prev2 = 0.0f;
  float p_prev = 0.0f, p_prev2 = 0.0f;  // and their positions
  int y_prev = 0;                       // prev's node.y without the leaf flag
  float h_sample_prev = NAN;            // the step before's sample (a peak must rise above it)
#if HFVIS_ROW_SPACING
  int position = 0;        // the current step's, in units
  uint unit_sum = 0;       // over the present samples before it: their steps' units,
  ulong weighted_sum = 0;  // and position * units
#endif
  int class_last = HFVIS_CONVEX;  // Eq. 1 class of prev2 (the first sample is convex)
  int head = HFVIS_NONE, tail = HFVIS_NONE;  // the root's first and last child
  float tail_h = 0.0f, tail_p = 0.0f;        // the last child's height and position
#if HFVIS_SAFE_ZONE
  SafeZone zone;
  int zone_valid = 0;
#endif
  uint zone_skips = 0;  // walks the safe zone skipped
  ulong total_m = 0, total_t = 0, total_naive = 0, total_visible = 0;
  int total_peaks = 0;  // peaks inserted
#if HFVIS_STRIPS
  __global TreeLineState* state = states + j;
  if (i_begin > 0) {
    const TreeLineState st = *state;
    HFVIS_LINE_REGISTERS(HFVIS_RESTORE)
  }
#endif

  int step = i_begin * n_samples;
  int col = line.x - i_begin * a, row = line.y - i_begin * b;  // the current period's receiver
  for (int i = i_begin; i < i_end; ++i, col -= a, row -= b) {
    const uint pixel = (uint)((row - out_row0) * width + col);
#if HFVIS_ROW_SPACING
    const int units = row_units[row];  // each step of this period
#endif
    for (int q = 0; q < n_samples; ++q, ++step) {
#if HFVIS_ROW_SPACING
      if (step > 0) position += units;
      line_positions[(uint)step * stride] = (int2)(position, (int)unit_sum);
      const float p_sample = (float)position;
#else
      const float p_sample = (float)(step << position_shift);
#endif
#if HFVIS_PEAK_PREPASS
      // The sample's height and the peak before it, as intervisibility_peaks wrote them.
      const int2 precomputed_peak = line_peak_inputs[(uint)PEAK_SLOT(step) * stride];
      const float h_sample = as_float(line_peak_inputs[(uint)SLOT_OF(step) * stride].x);
      const float h_peak = as_float(precomputed_peak.x);
      const int peak_position = precomputed_peak.y;
#else
#if HFVIS_ROW_SPACING
      // The step's whole units are its positions (a peak needs one strictly inside).
      const int step_scale = units, position_far = position - units;
#else
      const int step_scale = 1 << position_shift, position_far = (step - 1) << position_shift;
#endif
      const float d_sample = p_sample * inv_scale;  // (for the drop)
      const float h_sample = tree_sample_height(heights, width, height, row0, samples, q, i, col, row, drop, d_sample);
      int peak_position = 0;
      const float h_peak =
          tree_interval_peak(heights, width, height, row0, pieces, interval_first, q, i, col, row, step, h_sample_prev,
                             h_sample, drop, inv_scale, d_sample, position_far, step_scale, &peak_position);
#endif
      uint t = 0, skipped = 0;  // the step's convexity checks and skipped walks, its peak's included
      // The step's nodes: its peak (where there is one), then its sample.
      for (int part = 0; part < 2; ++part) {
        const int is_peak = part == 0, slot = 2 * step + part;
        const float h = is_peak ? h_peak : h_sample;
        const float p = is_peak ? (float)peak_position : p_sample;
        if (is_peak && isnan(h)) {
#if HFVIS_WANT_BOUNCE
          tree[(uint)slot * stride] =
              (int4)(as_int(NAN), 0, HFVIS_NONE, HFVIS_NONE);  // no peak: the gather skips it
#endif
          continue;
        }
        const uint e = (uint)slot * stride;
        const int receiver = !is_peak && q == n_samples - 1;
        if (!is_peak) {
#if HFVIS_ROW_SPACING && HFVIS_WANT_AREA
        prefix[base + e] = weighted_sum;
#elif HFVIS_HAS_NODATA && HFVIS_WANT_AREA  // step sums serve runs with holes only
        prefix[base + e] = step_sum;
#endif
      }
      if (isnan(h)) {
        tree[e] = (int4)(as_int(NAN), rank * 2, HFVIS_NONE, HFVIS_NONE);  // its rank, for clipped runs
#if HFVIS_WANT_ENTRY_STATS
        visible[base + e] = (float2)(NAN, NAN);
        entry_stats[base + e] = (uint4)(0u, 0u, 0u, 0u);
#endif
        if (receiver) {  // a nodata pixel
#if HFVIS_WANT_COUNT
          count_sum[pixel] = NAN;
#endif
#if HFVIS_WANT_AREA
          area_sum[pixel] = NAN;
#endif
#if HFVIS_WANT_BOUNCE
          for (int ch = 0; ch < HFVIS_CHANNELS; ++ch) irradiance[(uint)ch * plane + pixel] = NAN;
#endif
        }
        continue;
      }
      // A sample's node.y holds its rank, a peak's its position (it counts nothing).
      const int y_node = is_peak ? peak_position * 2 : rank * 2;
      uint m = 0, hash = 2166136261u;
      int count = 0;
      ulong distance_sum = 0;
#if HFVIS_WANT_BOUNCE
      BounceGather gather;
      if (receiver)
        bounce_begin(&gather, normals[pixel], normals[plane + pixel], normals[2u * plane + pixel],
                     cos_azimuth, sin_azimuth, step_ground, h, half_sector, wedge);
#endif
      if (root == HFVIS_NONE) {
        tree[e] = (int4)(as_int(h), HFVIS_LEAF, HFVIS_NONE, HFVIS_NONE);  // rank 0
        head = tail = HFVIS_NONE;
      } else {
        // 1. Algorithm 1 for the new root: the old root is its only child; the walk gives the
        // root's children in order.
        RootList list = {HFVIS_NONE, HFVIS_NONE, HFVIS_NONE, 0.0f, 0.0f};
        // The old root as the step before wrote it (its node is in registers: no load to wait on;
        // only a line's first node is a leaf while it is the root).
        const int4 old_root = (int4)(as_int(h_prev), y_prev + (prev2 == HFVIS_NONE ? HFVIS_LEAF : 0), head, HFVIS_NONE);
        int walk = 1;
#if HFVIS_REPLACEMENT_CHECK
        // The last child first (Sec. 7): when it fails, every child fails (their slopes from
        // the old root fall toward it) and the old root is replaced; inside the safe zone
        // nothing else changes and the walk is skipped (a walk leaves the zone invalid: it
        // runs only when the zone is). When it passes, the old root stays.
        int replaced = 0;
        if (tail != HFVIS_NONE) {
          ++t;
          replaced = chord_side(tail_h, h_prev, h, p_prev - tail_p, p - p_prev) <= 0;
        }
#endif
#if HFVIS_SAFE_ZONE
        zone_valid = zone_valid && replaced && safe_zone_inside(&zone, p, h);
        if (zone_valid) {
          // The old root's children are the new root's, and the old root is deleted (it is
          // no leaf: only a line's first sample is a leaf as root, and it has no children).
          walk = 0;
          ++skipped;
          list.head = head;
          list.tail = tail;
          list.tail_h = tail_h;
          list.tail_p = tail_p;
        }
#endif
#if !HFVIS_REPLACEMENT_CHECK
        const int replaced = 0;  // not known
#endif
        if (walk) {
#if HFVIS_DEFERRED_WRITES
          // The old root's level in registers: its children in order, each checked (unless
          // the last child's check decided it) and, when it fails, walked and appended; links
          // are written only where they change.
          int c = old_root.z;
          while (c != HFVIS_NONE) {
            const int4 child = tree[(uint)c * stride];
            if (!replaced) {
              if (HFVIS_REPLACEMENT_CHECK && c == tail) break;  // known to pass
              ++t;
              if (chord_side(as_float(child.x), h_prev, h,
                             p_prev - node_position(line_positions, stride, position_shift, c, child), p - p_prev) > 0)
                break;
            }
            t += hull_tree_walk(tree, line_positions, stride, position_shift, c, child, h, p, &list);
            c = child.w;
          }
          if (c != HFVIS_NONE || (old_root.y & HFVIS_LEAF)) {  // it stays, as the last child
            if (c != old_root.z) tree[(uint)root * stride].z = c;
            root_append(tree, stride, &list, root, h_prev, p_prev, HFVIS_NONE);
          }
#else
          t += hull_tree_walk(tree, line_positions, stride, position_shift, root, old_root, h, p, &list);
#endif
        }

        // 2. Now that the old root's next node is known, classify it (Eq. 1). A convex node
        // after a concave one starts a segment: if its node survived it is the root's last
        // child and becomes a leaf; otherwise a new leaf becomes the last child.
        if (prev2 != HFVIS_NONE) {
          const int side = chord_side(h_prev2, h_prev, h, p_prev - p_prev2, p - p_prev);
          const int cls = side > 0 ? HFVIS_CONVEX : side < 0 ? HFVIS_CONCAVE : class_last;
          if (cls == HFVIS_CONVEX && class_last == HFVIS_CONCAVE) {
            if (list.tail == prev) {
              tree[(uint)prev * stride].y = y_prev + HFVIS_LEAF;
            } else {
              tree[(uint)prev * stride] = (int4)(as_int(h_prev), y_prev + HFVIS_LEAF, HFVIS_NONE, HFVIS_NONE);
              root_append(tree, stride, &list, prev, h_prev, p_prev, HFVIS_NONE);
            }
          }
          class_last = cls;
        }
        if (!HFVIS_DEFERRED_WRITES || list.tail_next != HFVIS_NONE) tree[(uint)list.tail * stride].w = HFVIS_NONE;
        tree[e] = (int4)(as_int(h), y_node, list.head, HFVIS_NONE);
        head = list.head;
        tail = list.tail;
        tail_h = list.tail_h;
        tail_p = list.tail_p;

        // 3. At a receiver (at every sample for statistics), the visible samples from the
        // horizons, farthest first: the run of horizon hp ends at run_end() before the next
        // horizon np, or at the sample. Runs are slots; what they count are the samples among
        // them (SAMPLE_OF), never the peaks.
        // Without absent samples in between, ranks and distance sums follow from the steps
        // alone. The safe zone for the next samples is refreshed here, where the root's
        // children (the horizons) are visited anyway.
        if (receiver || HFVIS_ALL_HORIZONS) {
          // Within the maximum distance: the first step within max_steps of this one.
#if HFVIS_ROW_SPACING
          int cut = 0;
          if (position > max_steps) {  // positions rise along the line: bisection
            int hi = step;
            while (cut < hi) {
              const int mid = cut + (hi - cut) / 2;
              if (position - line_positions[(uint)mid * stride].x <= max_steps)
                hi = mid;
              else
                cut = mid + 1;
            }
          }
#else
          const int cut = step - max_steps;
#endif
#if HFVIS_SAFE_ZONE
          const int refresh_zone = !zone_valid;
          if (refresh_zone) safe_zone_begin(&zone, p, (float)(1 << position_shift));
#endif
          int hp = head;
          int4 hz = tree[(uint)hp * stride];
          int hp_rank = node_rank(tree, stride, hp, hz);
          // A horizon's run begins with the stretch of hidden samples farther out that it hides
          // only within the heights' rounding (forgiven_stretch): from slot run_first, of rank
          // run_first_rank. The farthest horizon's reaches back to the line's first sample. No
          // stretch goes past the maximum distance's cut: what lies beyond it does not count.
          int run_first = hp, run_first_rank = hp_rank;
          if (hp_rank > 0) {
            const int f = forgiven_stretch(
                tree, line_positions, stride, position_shift, max(cut, 0), hp, as_float(hz.x),
                node_position(line_positions, stride, position_shift, hp, hz), p, h, height_base);
            if (f >= 0) {
              run_first = SLOT_OF(f);
              run_first_rank =
                  HFVIS_HAS_NODATA ? tree[(uint)run_first * stride].y >> 1 : hp_rank - (SAMPLE_OF(hp) - f);
            }
          }
          for (;;) {
            const int np = hz.w;
            ++m;
#if HFVIS_SAFE_ZONE
            if (refresh_zone && hz.z != HFVIS_NONE) {
              const int4 g = tree[(uint)hz.z * stride];
              safe_zone_add(&zone, as_float(hz.x), node_position(line_positions, stride, position_shift, hp, hz),
                            as_float(g.x), node_position(line_positions, stride, position_shift, hz.z, g));
            }
#endif
            hash = (hash ^ (uint)hp) * 16777619u;
            int end = slot, end_rank = rank, np_rank = rank;
            int4 nz = hz;
            if (np != HFVIS_NONE) {
              nz = tree[(uint)np * stride];
              np_rank = node_rank(tree, stride, np, nz);
              end = np;
              end_rank = np_rank;
            }
            // Absent samples lie between present ones only where heights are missing: a line
            // enters the (convex) field once, and leaves it at its last receiver.
            const int holes = HFVIS_HAS_NODATA && end_rank - hp_rank != SAMPLE_OF(end) - SAMPLE_OF(hp);
            if (np != HFVIS_NONE) {
              end = run_end(tree, line_positions, stride, position_shift, hp, np, as_float(nz.x),
                            node_position(line_positions, stride, position_shift, np, nz), p, h, holes);
              end_rank = end == np ? np_rank
                         : holes   ? tree[(uint)end * stride].y >> 1
                                   : hp_rank + (SAMPLE_OF(end) - SAMPLE_OF(hp));
            }
            // The next horizon's run begins with its forgiven stretch, over the hidden samples
            // [end, np).
            int np_first = np, np_first_rank = np_rank;
            if (np != HFVIS_NONE && end != np) {
              const int f = forgiven_stretch(
                  tree, line_positions, stride, position_shift, max(SAMPLE_OF(end), cut), np, as_float(nz.x),
                  node_position(line_positions, stride, position_shift, np, nz), p, h, height_base);
              if (f >= 0) {
                np_first = SLOT_OF(f);
                np_first_rank =
                    HFVIS_HAS_NODATA ? tree[(uint)np_first * stride].y >> 1 : np_rank - (SAMPLE_OF(np) - f);
              }
            }
            // Absent samples within the run [run_first, end) (the ranks' and steps' closed forms
            // need none).
            const int run_holes =
                HFVIS_HAS_NODATA && end_rank - run_first_rank != SAMPLE_OF(end) - SAMPLE_OF(run_first);
#if HFVIS_WANT_BOUNCE
            // The run's visible samples and peaks. A peak (the surface's top between two samples,
            // which may hide every sample, as the rim of a pit of one pixel does off the axes)
            // shows where it is seen: the horizon itself, or before a sample of the run (the
            // visible nodes are a prefix), or seen over the next horizon; never in the forgiven
            // stretch before the horizon (peaks are not forgiven). It shows the radiance between
            // its two samples', weighted as its position lies between them.
            for (int x = run_first; receiver && x < end; ++x) {
              const int4 node = tree[(uint)x * stride];
              const float hx = as_float(node.x);
              if (isnan(hx)) continue;  // nodata, or no peak
              if (!IS_SAMPLE(x) &&
                  (x < hp ||
                   (x != hp && x + 1 >= end && np != HFVIS_NONE &&
                    !seen_over(hx, (float)(node.y >> 1), as_float(nz.x),
                               node_position(line_positions, stride, position_shift, np, nz), h, p))))
                continue;
              float emitted[HFVIS_CHANNELS];
              lattice_radiance(radiance, width, plane, line, samples, n_samples, a, b, SAMPLE_OF(x), emitted);
              float distance = (float)(step - SAMPLE_OF(x));
              if (!IS_SAMPLE(x)) {
                const int offset = (node.y >> 1) - ((SAMPLE_OF(x) - 1) << position_shift);
                const float toward = (float)offset * inv_scale;  // of the step, from the sample before
                float before[HFVIS_CHANNELS];
                lattice_radiance(radiance, width, plane, line, samples, n_samples, a, b, SAMPLE_OF(x) - 1,
                                 before);
                for (int c = 0; c < HFVIS_CHANNELS; ++c)
                  emitted[c] = before[c] + toward * (emitted[c] - before[c]);
                distance += 1.0f - toward;
              }
              bounce_visit(&gather, hx, distance, emitted);
            }
            // No hidden sample before the next visible one: the run reached the next one's.
            gather.adjacent = gather.adjacent && end == np_first;
#endif
            // Within the maximum distance only the run's samples from `first` on count (terrain
            // farther away neither counts nor hides anything nearer): from the slot of the first
            // step within it (its peak's). Every sample's slot holds its rank.
            const int first = cut > SAMPLE_OF(run_first) ? PEAK_SLOT(cut) : run_first;
            const int first_rank = first == run_first ? run_first_rank
                                   : run_holes        ? tree[(uint)SLOT_OF(SAMPLE_OF(first)) * stride].y >> 1
                                               : run_first_rank + (SAMPLE_OF(first) - SAMPLE_OF(run_first));
            const int run = first < end ? end_rank - first_rank : 0;
            count += run;
#if HFVIS_WANT_AREA
            // Sum of (step - x) over the counted present samples x.
#if HFVIS_ROW_SPACING
            // Sum of (position - x's) * x's units over the counted present samples x (the
            // sums at `step` are those before it, written above).
            // Positions are per step, the sums per sample slot: the counted samples are steps
            // SAMPLE_OF(first) .. SAMPLE_OF(end) - 1 (a peak's step is that of the sample after it).
            if (run > 0) {
              const uint s_first = (uint)SAMPLE_OF(first), s_end = (uint)SAMPLE_OF(end);
              const uint units_run =
                  (uint)line_positions[s_end * stride].y - (uint)line_positions[s_first * stride].y;
              distance_sum += (ulong)position * (ulong)units_run -
                              (prefix[base + (uint)SLOT_OF(s_end) * stride] - prefix[base + (uint)SLOT_OF(s_first) * stride]);
            }
#else
            ulong steps_sum = 0;
            if (run == 0) {
            } else if (!run_holes) {  // x = first .. end - 1
              steps_sum = (ulong)run * (ulong)(SAMPLE_OF(first) + SAMPLE_OF(end) - 1) / 2;
            } else {
              const ulong end_sum = end == slot ? step_sum : prefix[base + (uint)SLOT_OF(SAMPLE_OF(end)) * stride];
              steps_sum = end_sum - prefix[base + (uint)SLOT_OF(SAMPLE_OF(first)) * stride];
            }
            distance_sum += (ulong)step * (ulong)run - steps_sum;
#endif
#endif
            if (np == HFVIS_NONE) break;
            hz = nz;
            hp = np;
            hp_rank = np_rank;
            run_first = np_first;
            run_first_rank = np_first_rank;
          }
#if HFVIS_SAFE_ZONE
          if (refresh_zone) {
            safe_zone_end(&zone);
            zone_valid = 1;
          }
#endif
        }
      }
      if (receiver) {
#if HFVIS_ROW_SPACING
        const float2 factors = row_factors[row];
        count_factor = factors.x;
        area_factor = factors.y;
#endif
#if HFVIS_WANT_COUNT
        count_sum[pixel] += count_factor * (float)count;
#endif
#if HFVIS_WANT_AREA
        area_sum[pixel] += area_factor * (float)distance_sum;
#endif
#if HFVIS_WANT_BOUNCE
        float gathered[HFVIS_CHANNELS];
        bounce_finish(&gather, gathered);
        for (int ch = 0; ch < HFVIS_CHANNELS; ++ch) irradiance[(uint)ch * plane + pixel] += gathered[ch];
#endif
      }
      prev2 = prev;
      h_prev2 = h_prev;
      p_prev2 = p_prev;
      prev = slot;
      h_prev = h;
      p_prev = p;
      y_prev = y_node;
      root = slot;
      if (is_peak) {  // (its horizons count in the statistics' bound, t <= 2 m + n, n its nodes)
        ++total_peaks;
        total_m += m;
        continue;
      }
#if HFVIS_WANT_ENTRY_STATS
      visible[base + e] = (float2)((float)count, (float)distance_sum);
      entry_stats[base + e] = (uint4)(m, t, hash, skipped);
#endif
      total_m += m;
      total_naive += (ulong)rank;
      total_visible += (ulong)count;
      ++rank;
      step_sum += (ulong)step;
#if HFVIS_ROW_SPACING
      // The sample's ring width: the units of its step toward the receivers (into the next
      // period at a receiver; the line's last sample is no one's farther sample).
      const int ring = receiver && i + 1 < line.z ? row_units[row - b] : units;
      unit_sum += (uint)ring;
      weighted_sum += (ulong)position * (ulong)ring;
#endif
      }
      total_t += t;
      zone_skips += skipped;
      h_sample_prev = h_sample;
    }
  }
#if HFVIS_STRIPS
  TreeLineState st;
  HFVIS_LINE_REGISTERS(HFVIS_SAVE)
  *state = st;
#endif
#if HFVIS_WANT_STATS  // (in strips: the totals so far)
  __global ulong* totals = line_totals + (uint)(first_line + j) * HFVIS_LINE_TOTALS;
  totals[0] = (ulong)rank;
  totals[1] = total_m;
  totals[2] = total_t;
  totals[3] = total_naive;
  totals[4] = total_visible;
  totals[5] = (ulong)zone_skips;
  totals[6] = (ulong)total_peaks;
  totals[7] = 0;
#endif
}

// ---------------------------------------------------------------------------------------
// The naive method.
//
// Visible ground area (the "total viewshed"): around receiver p, direction k stands for
// the azimuthal sector 2*pi/K, and a sample at distance rho (ground units) along it for
// the ring of width drho = step_length * ground_per_pixel between rho -/+ drho/2, whose
// sector has area (2*pi/K) * rho * drho. With rho = i * drho for the sample i steps away,
// direction k adds (2*pi/K) * drho^2 * (sum of i over the visible samples). On a flat
// field this tends to the field's area seen from p as K grows. The sweep does the same
// with its own step and each direction's share of the circle.

#if HFVIS_ROW_SPACING
// Index in a half-row table of the middle of step i of a ray from row `row` (i - 0.5 = `mid`
// steps of step_y rows along it): rint(2 y), clamped to the field (samples outside are absent).
HFVIS_INLINE int ray_half_row(float row, float mid, float step_y, int height) {
  return clamp((int)rint(2.0f * (row + mid * step_y)), 0, 2 * height - 2);
}

// Step i of a ray from row rr: its units into *ring, the position it reaches (*position, the
// running sum) returned.
HFVIS_INLINE int ray_step(__global const int* units, int rr, int i, float step_y, int height, int* position,
                          int* ring) {
  *ring = units[ray_half_row((float)rr, (float)i - 0.5f, step_y, height)];
  *position += *ring;
  return *position;
}
#endif

// Adds one direction's visible samples (count and distance sum in steps) to the sums.
HFVIS_INLINE void add_direction(const SweepDirection d, float sector, float count, float distance_steps,
                                float* count_sum, float* area_sum) {
  float ground = d.step_length * d.ground_per_pixel;
  *count_sum += count;
  *area_sum += sector * ground * ground * distance_steps;
}

HFVIS_INLINE void accumulate_visible(uint pixel, int nodata, float count, float area,
                                     __global float* count_sum, __global float* area_sum) {
  count_sum[pixel] = nodata ? NAN : count_sum[pixel] + count;
#if HFVIS_WANT_AREA
  area_sum[pixel] = nodata ? NAN : area_sum[pixel] + area;
#endif
}

// Naive method (Timonen 2013, Sec. 1): for every pixel, march the ray in steps of
// step_length pixels, sample bilinearly, and count the samples that reach the steepest
// slope so far (the same tie rule and predicate as the sweep), and the hidden ones after such
// a sample that it hides only within the heights' rounding, up to the first that it hides
// beyond it (forgiven_stretch's rule). The trip count is uniform
// over the work-group (the longest ray of its tile), as in horizon_naive; samples outside
// the field are masked. Global size: (W, H) rounded up to the local size.
// With HFVIS_ROW_SPACING the ray is straight in pixels and positions along it are whole
// units of ground length (as the tree's): direction b's step whose middle is at row y has
// row_units[b * (2 height - 1) + rint(2 y)] units (half-row table), a sample's ring width is
// its step toward the receiver, and a receiver of row r adds row_factors[b * height + r]
// (count factor, area factor per unit squared) times its count and its sum of position *
// ring units; `curvature` is then the drop per unit squared and max_steps counts units.
__kernel void intervisibility_naive(__global const float* heights, int width, int height,
                                    __global const SweepDirection* directions, int batch_size, float sector,
                                    float curvature, __global const int* max_steps,
                                    __global const int* row_units, __global const float2* row_factors,
                                    __global float* count_sum, __global float* area_sum, float height_base) {
  int c = get_global_id(0), r = get_global_id(1);
  int c_lo = get_group_id(0) * get_local_size(0), r_lo = get_group_id(1) * get_local_size(1);
  int c_hi = min(c_lo + (int)get_local_size(0), width) - 1;
  int r_hi = min(r_lo + (int)get_local_size(1), height) - 1;
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  float h = heights[pixel];
  float counts = 0.0f, area = 0.0f;
  for (int b = 0; b < batch_size; ++b) {
    const SweepDirection d = load_direction(directions + b);
    const float far = (float)(width + height);
    float reach_x = d.dir_x > 0.0f   ? ((float)(width - 1) - (float)c_lo) / d.dir_x
                    : d.dir_x < 0.0f ? (float)c_hi / -d.dir_x
                                     : far;
    float reach_y = d.dir_y > 0.0f   ? ((float)(height - 1) - (float)r_lo) / d.dir_y
                    : d.dir_y < 0.0f ? (float)r_hi / -d.dir_y
                                     : far;
    int steps = (int)(fmin(fmin(reach_x, reach_y), far) * d.samples_per_unit) + 1;
#if HFVIS_ROW_SPACING
    const float drop = curvature;
    __global const int* units = row_units + b * (2 * height - 1);
    const float step_y = d.step_length * d.dir_y;
#else
    // The Earth's drop per step squared (0 without curvature).
    const float step_ground = d.step_length * d.ground_per_pixel;
    const float drop = curvature * step_ground * step_ground;
#endif
    const int counted_steps = max_steps[b];  // samples farther away are not counted
    float best_h = 0.0f;  // the steepest sample so far (the latest visible one)
    int best_step = 0;    // its position, 0 = none yet
    int forgiving = 0;    // every hidden sample since it was forgiven its rounding
    int count = 0, undecided = 0;
    uint distance_sum = 0;
#if HFVIS_ROW_SPACING
    int position = 0;
    float weighted = 0.0f;  // sum of position * ring units over the counted samples
#endif
    for (int i = 1; i <= steps; ++i) {
      // `steps` is the same for the whole work-group, so every work-item reaches this
      // barrier; it makes PoCL run the work-items inside each step, the loop it vectorises
      // (as in horizon_naive). Only the filter runs here: an exact fallback inside would
      // keep the loop scalar (7x slower).
      barrier(CLK_LOCAL_MEM_FENCE);
      float t = (float)i * d.step_length;
      float px = (float)cc + t * d.dir_x, py = (float)rr + t * d.dir_y;
      float q = sample_height_from(heights, width, height, cc, rr, t * d.dir_x, t * d.dir_y);
#if HFVIS_ROW_SPACING
      int ring;
      const int at = ray_step(units, rr, i, step_y, height, &position, &ring);
#else
      const int at = i;
#endif
#if HFVIS_CURVATURE
      q = q - drop * (float)at * (float)at;
#endif
      int present = inside_field(px, py, width, height) && !isnan(q);
      int side, side_forgiven;
      // best_step = 0 (none yet) would make the chord degenerate; its answers are ignored.
      const float dab = (float)(at - best_step), dbc = (float)max(best_step, 1);
      int decided = chord_side_filter(q, best_h, h, dab, dbc, &side);
      const float slack = rounding_forgiven(q, best_h, h, height_base);
      int decided_forgiven = chord_side_filter(q + slack, best_h - slack, h, dab, dbc, &side_forgiven);
      undecided |= present && best_step > 0 && !(decided && (side <= 0 || !forgiving || decided_forgiven));
      int visible = present && (best_step == 0 || side <= 0);
      int seen = visible || (present && forgiving && side_forgiven <= 0);
      forgiving = present ? seen : forgiving;
      int counted = seen && at <= counted_steps;
      count += counted;
#if HFVIS_ROW_SPACING
      weighted += counted ? (float)at * (float)ring : 0.0f;
#else
      distance_sum += counted ? (uint)i : 0u;
#endif
      best_h = visible ? q : best_h;
      best_step = visible ? at : best_step;
    }
    if (undecided) {  // a near-tie somewhere on this ray: march it again, exactly
      best_h = 0.0f;
      best_step = count = forgiving = 0;
      distance_sum = 0;
#if HFVIS_ROW_SPACING
      position = 0;
      weighted = 0.0f;
#endif
      for (int i = 1; i <= steps; ++i) {
        float t = (float)i * d.step_length;
        float px = (float)cc + t * d.dir_x, py = (float)rr + t * d.dir_y;
        float q = sample_height_from(heights, width, height, cc, rr, t * d.dir_x, t * d.dir_y);
#if HFVIS_ROW_SPACING
        int ring;
        const int at = ray_step(units, rr, i, step_y, height, &position, &ring);
#else
        const int at = i;
#endif
#if HFVIS_CURVATURE
        q = q - drop * (float)at * (float)at;
#endif
        if (!inside_field(px, py, width, height) || isnan(q)) continue;
        const float dab = (float)(at - best_step), dbc = (float)best_step;
        const int hidden = best_step > 0 && chord_side(q, best_h, h, dab, dbc) > 0;
        if (hidden) forgiving = forgiving && seen_within_rounding(q, best_h, h, dab, dbc, height_base);
        if (hidden && !forgiving) continue;
        if (at <= counted_steps) {
          ++count;
#if HFVIS_ROW_SPACING
          weighted += (float)at * (float)ring;
#else
          distance_sum += (uint)i;
#endif
        }
        if (hidden) continue;
        forgiving = 1;
        best_h = q;
        best_step = at;
      }
    }
#if HFVIS_ROW_SPACING
    const float2 factors = row_factors[b * height + rr];
    counts += factors.x * (float)count;
    area += factors.y * weighted;
#else
    add_direction(d, sector, (float)count, (float)distance_sum, &counts, &area);
#endif
  }
  if (valid) accumulate_visible(pixel, isnan(h), counts, area, count_sum, area_sum);
}
