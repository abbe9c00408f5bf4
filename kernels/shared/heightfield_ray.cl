// heightfield_ray.cl: the first hit of the bilinear surface along a 3D ray, and the view cells
// (hfvis/pvs.hpp) the free part of the ray passes through. Written once in the common subset of
// OpenCL C and C++, as shared/region_visibility_sight.cl is: kernels/pvs.cl includes it, and so
// does src/ops/pvs_ray.hpp (inside namespace hfvis::detail), so the kernel and the scalar
// reference run the very same float operations (no contraction into fma on either side, no math
// library call but the correctly rounded division and square root).
//
// Positions are in pixels (x along columns, y along rows) and heights z-scaled; a ray is
// o + t d for t in [0, t_max]. The surface is the bilinear one of the viewshed and the region
// visibility: inside each cell between four grid points h(x, y) = h00 + (h10 - h00) u +
// (h01 - h00) v + twist u v, so along a ray the height over the surface is a quadratic in t
// within a cell: the hit is its root, solved per cell. The ray hits where it first passes
// strictly below the surface (the line-of-sight test's "rises strictly above": a ray that only
// touches the surface goes on); a ray starting below it hits at once. A cell with a nodata
// corner has no surface: the ray passes through it.
//
// Empty space is skipped with a maximum pyramid over the grid points (the viewshed's layout:
// level k >= 1 holds, per block of 2^k x 2^k cells, the largest of its (2^k + 1)^2 heights, NaN
// where all are nodata; level k is levels[4k] blocks wide, levels[4k + 1] high, from
// levels[4k + 2]): a block is skipped where the ray over it stays above its largest height by
// more than `clearance` (0 for the hit alone; the view band's top when view cells are wanted,
// but 0 where the ray crosses the block inside the view cell it listed last).
#ifndef HFVIS_HEIGHTFIELD_RAY_CL
#define HFVIS_HEIGHTFIELD_RAY_CL

#include "region_visibility_sight.cl"

// The cell holding coordinate p of a point moving by d: a point on a boundary belongs to the cell
// the ray enters there.
inline int hf_ray_cell_of(float p, float d, int cells) {
  const float c = d < 0.0f ? ceil(p) - 1.0f : floor(p);
  return c < 0.0f ? 0 : (c > (float)(cells - 1) ? cells - 1 : (int)c);
}

// The ray parameter where coordinate o + t d reaches `line` (INFINITY when d = 0).
inline float hf_ray_crossing(float line, float o, float d) { return d != 0.0f ? (line - o) / d : INFINITY; }

// The bilinear surface of a cell with corners h00 (its lower corner), h10, h01, h11 at (u, v)
// from its lower corner, clamped into the cell; NaN where a corner is nodata.
inline float hf_ray_bilinear(float h00, float h10, float h01, float h11, float u, float v) {
  u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
  v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
  const float a = h00 + (h10 - h00) * u;
  const float b = h01 + (h11 - h01) * u;
  return a + (b - a) * v;
}

// The vertex of g (below), where bump != 0.
inline float hf_ray_vertex(float f0, float f1, float bump) { return 0.5f + (f1 - f0) / (2.0f * bump); }

// g(s) = f0 + (f1 - f0) s + bump s (1 - s): the surface minus the ray over one cell's piece,
// in the piece's own parameter s in [0, 1].
inline float hf_ray_piece(float f0, float f1, float bump, float s) {
  return f0 + (f1 - f0) * s + bump * s * (1.0f - s);
}

// The least s in [0, s_end] where g turns positive, given g(0) <= 0 < g somewhere in
// (0, s_end]: the smaller root where g is concave (bump > 0), the larger where convex.
inline float hf_ray_entry(float f0, float f1, float bump, float s_end) {
  // g(s) = A s^2 + B s + C. The root of the line (A = 0) and those of the quadratic are both
  // computed and the one that applies taken: a branch on A, which is 0 on every planar cell
  // (most of a city's), would be mispredicted often. Where A = 0 the quadratic's roots are
  // computed with a divisor of 1 instead (not taken; no division by zero in the C++ reference).
  // B = 0 with A = 0 is the old code's case too: its infinity or NaN is what the line gives.
  const float A = -bump, B = f1 - f0 + bump, C = f0;
  const float s_line = -C / B;
  float disc = B * B - 4.0f * A * C;
  disc = disc < 0.0f ? 0.0f : disc;  // a tangent rounded below zero
  const float root = sqrt(disc);
  const float q = -0.5f * (B < 0.0f ? B - root : B + root);
  const float r1 = q / (A == 0.0f ? 1.0f : A), r2 = q != 0.0f ? C / q : r1;
  const float lo = r1 < r2 ? r1 : r2, hi = r1 < r2 ? r2 : r1;
  const float s = A == 0.0f ? s_line : (A < 0.0f ? lo : hi);
  if (isnan(s)) return s_end;
  return s < 0.0f ? 0.0f : (s > s_end ? s_end : s);
}

// A point of [0, s_end] where g lies in [lo, hi] (the view band, g being minus the height over the
// surface), given that g's range over [0, s_end] (its ends and its vertex sv) meets it: an end
// where it lies in the band, else where g first reaches the band (the entry of g - lo from below,
// of hi - g from above, solved as the hit is; a band of one height, H0 = H1, holds it only to
// rounding); where rounding puts that root outside a wider band, the vertex or a bisection
// between a point below and one above.
inline float hf_ray_band_point(float f0, float f1, float bump, float s_end, float sv, float lo, float hi) {
  // The ends and the root are all computed and the answer selected: whether an end lies in a
  // band of one height (H0 = H1) is a matter of rounding, and a branch on it would be
  // mispredicted about every other time.
  const float ge = hf_ray_piece(f0, f1, bump, s_end);
  const int below = f0 < lo;
  const float root =
      hf_ray_entry(below ? f0 - lo : hi - f0, below ? f1 - lo : hi - f1, below ? bump : -bump, s_end);
  const int f0_in = (f0 >= lo) & (f0 <= hi), ge_in = (ge >= lo) & (ge <= hi);
  const float found = f0_in ? 0.0f : (ge_in ? s_end : root);
  if (f0_in | ge_in | (lo == hi)) return found;  // a band of one height: met to rounding
  const float g_root = hf_ray_piece(f0, f1, bump, root);
  if (g_root >= lo && g_root <= hi) return root;
  float s_low = f0 < lo ? 0.0f : s_end, s_high = f0 > hi ? 0.0f : s_end;
  if (sv > 0.0f && sv < s_end) {
    const float gv = hf_ray_piece(f0, f1, bump, sv);
    if (gv >= lo && gv <= hi) return sv;
    if (gv < lo) s_low = sv;
    if (gv > hi) s_high = sv;
  }
  float s = 0.5f * (s_low + s_high);
  for (int i = 0; i < 40; ++i) {
    s = 0.5f * (s_low + s_high);
    // Once the midpoint rounds to an end the bracket cannot shrink: every further step would
    // find this s again (a band of one height, H0 = H1, is met exactly almost never).
    if (s == s_low || s == s_high) break;
    const float g = hf_ray_piece(f0, f1, bump, s);
    if (g >= lo && g <= hi) break;
    if (g < lo)
      s_low = s;
    else
      s_high = s;
  }
  return s;
}

// Whether a ray bends (C != 0, hf_ray_cast): a program built for a flat surface alone
// (-DHF_RAY_FLAT, src/ops/pvs.cpp) drops the test and the curved terms, so that flat runs cast
// as they did before curvature; the C++ reference and curved programs test C.
#ifdef HF_RAY_FLAT
#define HF_RAY_CURVED(C) 0
#else
#define HF_RAY_CURVED(C) ((C) != 0.0f)
#endif

// The ray's height at t: oz + t dz, and with curvature + C t^2. (Only then: a vertical ray, C = 0,
// may run to t = INFINITY, where C t^2 would be NaN.)
inline float hf_ray_height(float oz, float dz, float C, float t) {
  return HF_RAY_CURVED(C) ? oz + t * dz + C * t * t : oz + t * dz;
}

// Casts the ray o + t d, t in [0, t_max], through the field's box [0, width - 1] x [0, height - 1]
// (a ray starting outside it enters first). Returns the hit's t, *cell = its cell (cy (width - 1)
// + cx); or where the ray leaves the box or reaches t_max, *cell = -1.
//
// With curvature c (the drop coefficient of hfvis/viewshed.hpp, per ground unit: a drop c d^2; cells
// cell_x x cell_y ground units), the ray is a straight line over a curved surface: a point at
// ground distance d from o lies c d^2 lower relative to it, so over the grid its height is
// oz + t dz + C t^2, C = c ((dx cell_x)^2 + (dy cell_y)^2) (the region visibility's c D^2 t (1 - t)
// between two points of it). Along a cell the height over the surface is still a quadratic in t:
// C adds to its curvature (bump), and a block is skipped by the ray's lowest point over it (an
// end, or the vertex where C > 0). c = 0 gives the straight ray's operations exactly.
//
// With `cap` > 0, also the view cells (squares of `view` x `view` cells, view_x across) whose band
// the ray passes through before the hit: the points whose height above the surface lies in
// [band_lo, band_hi]; each one once, in order along the ray, entry j at pierced[j * stride] with
// a t of such a point at pierced_t[j * stride]; *count of them (at most cap: a segment meets at
// most view_x + view_y - 1 squares).
inline float hf_ray_cast_within(HFVIS_GLOBAL const float* h, int width, int height,
                                HFVIS_GLOBAL const float* pyramid, HFVIS_GLOBAL const int* levels, int top,
                                float ox, float oy, float oz, float dx, float dy, float dz, float t_max,
                                float curvature, float cell_x, float cell_y, int view, int view_x,
                                float band_lo, float band_hi, int cap, HFVIS_GLOBAL int* pierced,
                                HFVIS_GLOBAL float* pierced_t, int stride, int* count, int* cell) {
  const int cells_x = width - 1, cells_y = height - 1;
  const float gx = dx * cell_x, gy = dy * cell_y;
  const float C = curvature * (gx * gx + gy * gy);
  // The vertex of the ray's height (its lowest point where C > 0; never reached where C <= 0).
  const float t_vertex = HF_RAY_CURVED(C) && C > 0.0f ? -dz / (2.0f * C) : -INFINITY;
  *cell = -1;
  *count = 0;
  // Clip to the box.
  float t_lo = 0.0f, t_hi = t_max;
  if (dx != 0.0f) {
    const float a = (0.0f - ox) / dx, b = ((float)cells_x - ox) / dx;
    t_lo = (a < b ? a : b) > t_lo ? (a < b ? a : b) : t_lo;
    t_hi = (a < b ? b : a) < t_hi ? (a < b ? b : a) : t_hi;
  } else if (ox < 0.0f || ox > (float)cells_x) {
    return 0.0f;
  }
  if (dy != 0.0f) {
    const float a = (0.0f - oy) / dy, b = ((float)cells_y - oy) / dy;
    t_lo = (a < b ? a : b) > t_lo ? (a < b ? a : b) : t_lo;
    t_hi = (a < b ? b : a) < t_hi ? (a < b ? b : a) : t_hi;
  } else if (oy < 0.0f || oy > (float)cells_y) {
    return 0.0f;
  }
  if (!(t_lo <= t_hi)) return t_lo < t_max ? t_lo : t_max;
  const float clearance = cap > 0 ? band_hi : 0.0f;
  const int sx = dx < 0.0f ? -1 : 1, sy = dy < 0.0f ? -1 : 1;
  // The cells [view_x0, view_x1) x [view_y0, view_y1) of the view cell listed last (none yet),
  // and the t where the ray leaves their square: a block the ray crosses before that holds no
  // view cell still to list, so it is skipped as for the hit alone (clearance 0), and a cell
  // among them lists nothing. A ray in the band over most of its way (rays from the band,
  // grazing rays) would otherwise be marched cell by cell through the view cell it listed first.
  int view_x0 = 0, view_x1 = 0, view_y0 = 0, view_y1 = 0;
  float listed_to = -INFINITY;
  float t = t_lo;
  int k = top > 0 ? 1 : 0;
  // Where the last level-1 block that could not be skipped ends: its cells are marched one
  // after another up to there, without testing the block again.
  float march_to = t_lo;
  // The surface minus the ray where the last marched cell ended, carried into the next cell
  // when it follows at once (NaN: none).
  float carried = NAN;
  // The point at t and the cell holding it (cx, cy): a block of 2^k x 2^k cells holds it where
  // it holds that cell, block (cx >> k, cy >> k) (the cell of x / 2^k, x / 2^k being exact), so
  // the point's cell is found once per t, not once per level.
  float x = ox + t * dx, y = oy + t * dy;
  int cx = hf_ray_cell_of(x, dx, cells_x), cy = hf_ray_cell_of(y, dy, cells_y);
  for (;;) {
    if (k > 0) {
      const int size = 1 << k, bw = levels[4 * k];
      const int bx = cx >> k, by = cy >> k;
      const float ex = hf_ray_crossing((float)((dx < 0.0f ? bx : bx + 1) * size), ox, dx);
      const float ey = hf_ray_crossing((float)((dy < 0.0f ? by : by + 1) * size), oy, dy);
      float te = ex < ey ? ex : ey;
      te = te < t_hi ? te : t_hi;
      const float za = hf_ray_height(oz, dz, C, t), zb = hf_ray_height(oz, dz, C, te);
      float low = za < zb ? za : zb;
      if (t_vertex > t && t_vertex < te) {
        const float zv = hf_ray_height(oz, dz, C, t_vertex);
        low = zv < low ? zv : low;
      }
      const float top_height = pyramid[levels[4 * k + 2] + by * bw + bx];
      const float above = te <= listed_to ? 0.0f : clearance;
      if (te > t && !(low - top_height <= above)) {  // above the block (or the block all nodata)
        if (te >= t_hi) return t_hi;
        t = te;
        x = ox + t * dx;
        y = oy + t * dy;
        cx = hf_ray_cell_of(x, dx, cells_x);
        cy = hf_ray_cell_of(y, dy, cells_y);
        k = k < top ? k + 1 : top;
        carried = NAN;
      } else {
        if (k == 1) march_to = te;
        --k;
      }
      continue;
    }
    // One cell: the one holding the point, stepped past the cells whose exit rounding put behind t.
    float tx = hf_ray_crossing((float)(dx < 0.0f ? cx : cx + 1), ox, dx);
    float ty = hf_ray_crossing((float)(dy < 0.0f ? cy : cy + 1), oy, dy);
    while (tx <= t || ty <= t) {
      if (tx <= t) {
        cx += sx;
        tx = hf_ray_crossing((float)(dx < 0.0f ? cx : cx + 1), ox, dx);
      } else {
        cy += sy;
        ty = hf_ray_crossing((float)(dy < 0.0f ? cy : cy + 1), oy, dy);
      }
      if (cx < 0 || cx >= cells_x || cy < 0 || cy >= cells_y) return t_hi;
    }
    float t1 = tx < ty ? tx : ty;
    t1 = t1 < t_hi ? t1 : t_hi;
    const int p = cy * width + cx;
    const float h00 = h[p], h10 = h[p + 1], h01 = h[p + width], h11 = h[p + width + 1];
    const float s1 = hf_ray_bilinear(h00, h10, h01, h11, ox + t1 * dx - (float)cx, oy + t1 * dy - (float)cy);
    // The surface at the cell's entry: the last cell's exit where the march goes on into this
    // one (the same point of the continuous surface), else evaluated here.
    const float f0 = !isnan(carried) ? carried
                                     : hf_ray_bilinear(h00, h10, h01, h11, x - (float)cx, y - (float)cy) -
                                           hf_ray_height(oz, dz, C, t);
    const float f1 = s1 - hf_ray_height(oz, dz, C, t1);
    carried = NAN;
    if (!isnan(f0) && !isnan(f1)) {
      const float span = t1 - t;
      const float twist = h00 - h10 - h01 + h11;
      const float bump = HF_RAY_CURVED(C) ? -(twist * dx * dy) * span * span + C * span * span
                                          : -(twist * dx * dy) * span * span;
      // Where the piece turns positive, if it does: s_end.
      float s_end = 1.0f;
      int hit = 0;
      // g's vertex (its top where bump > 0, its bottom where bump < 0; -1 for none).
      float sv = -1.0f;
      if (bump != 0.0f) sv = hf_ray_vertex(f0, f1, bump);
      // The piece turns positive where it ends above the surface, or where its top is above
      // (the first root before the vertex); whichever, one root is solved (taken without a
      // branch per case: which case holds is a toss-up from cell to cell).
      const int ends_above = f1 > 0.0f;
      const int top_above =
          (bump > 0.0f) & (sv > 0.0f) & (sv < 1.0f) & (hf_ray_piece(f0, f1, bump, sv) > 0.0f);
      if (f0 > 0.0f) {
        s_end = 0.0f;
        hit = 1;
      } else if (ends_above | top_above) {
        s_end = hf_ray_entry(f0, f1, bump, ends_above ? 1.0f : sv);
        hit = 1;
      }
      // A view cell not listed last (a segment meets each view cell's square once).
      if (cap > 0 && !(cx >= view_x0 && cx < view_x1 && cy >= view_y0 && cy < view_y1) && *count < cap) {
        // g's range over [0, s_end] against the band -band_hi <= g <= -band_lo.
        const float ge = hf_ray_piece(f0, f1, bump, s_end);
        float g_min = f0 < ge ? f0 : ge, g_max = f0 < ge ? ge : f0;
        if (sv > 0.0f && sv < s_end) {
          const float gv = hf_ray_piece(f0, f1, bump, sv);
          g_max = gv > g_max ? gv : g_max;
          g_min = gv < g_min ? gv : g_min;
        }
        if (g_max >= -band_hi && g_min <= -band_lo) {
          const float s = hf_ray_band_point(f0, f1, bump, s_end, sv, -band_hi, -band_lo);
          pierced[*count * stride] = (cy / view) * view_x + cx / view;
          pierced_t[*count * stride] = t + s * span;
          ++*count;
          view_x0 = (cx / view) * view;
          view_y0 = (cy / view) * view;
          view_x1 = view_x0 + view;
          view_y1 = view_y0 + view;
          const float lx = hf_ray_crossing((float)(dx < 0.0f ? view_x0 : view_x1), ox, dx);
          const float ly = hf_ray_crossing((float)(dy < 0.0f ? view_y0 : view_y1), oy, dy);
          listed_to = lx < ly ? lx : ly;
        }
      }
      if (hit) {
        *cell = cy * cells_x + cx;
        return t + s_end * span;
      }
    }
    if (t1 >= t_hi) return t_hi;
    t = t1;
    x = ox + t * dx;
    y = oy + t * dy;
    cx = hf_ray_cell_of(x, dx, cells_x);
    cy = hf_ray_cell_of(y, dy, cells_y);
    // On through the block that could not be skipped; past it, test blocks again.
    if (t1 < march_to) {
      carried = f1;
    } else {
      k = top > 0 ? 1 : 0;
    }
  }
}

// hf_ray_cast_within, and a vertical ray (no ground motion: it never crosses a grid line of the cell
// it starts in, a direction of 0 across or too small to reach one) with no end: it stays over one
// point, so its one cell would end at t = INFINITY, where x = ox + t dx is 0 * INFINITY (NaN) and
// no hit is seen (a ray straight down from above the surface went through it). It is cast to
// where it has passed below the lowest corner of the cell under it (going down) or above its
// highest corner and the band (going up), by a margin its heights' float spacing cannot swallow,
// beyond which nothing can happen to it (a ray of no direction: to t = 0, where it hits if it
// starts below the surface); and without a hit it is reported unbounded, as before. (Over a
// nodata corner the bound is not finite: no surface, nothing to hit.)
inline float hf_ray_cast(HFVIS_GLOBAL const float* h, int width, int height,
                         HFVIS_GLOBAL const float* pyramid, HFVIS_GLOBAL const int* levels, int top, float ox,
                         float oy, float oz, float dx, float dy, float dz, float t_max, float curvature,
                         float cell_x, float cell_y, int view, int view_x, float band_lo, float band_hi,
                         int cap, HFVIS_GLOBAL int* pierced, HFVIS_GLOBAL float* pierced_t, int stride,
                         int* count, int* cell) {
  float t_end = t_max;
  const int inside = ox >= 0.0f && ox <= (float)(width - 1) && oy >= 0.0f && oy <= (float)(height - 1);
  if (!(t_max < INFINITY) && inside) {
    const int cx = hf_ray_cell_of(ox, dx, width - 1), cy = hf_ray_cell_of(oy, dy, height - 1);
    const float tx = hf_ray_crossing((float)(dx < 0.0f ? cx : cx + 1), ox, dx);
    const float ty = hf_ray_crossing((float)(dy < 0.0f ? cy : cy + 1), oy, dy);
    if (!(tx < INFINITY) && !(ty < INFINITY)) {
      const int p = cy * width + cx;
      const float h00 = h[p], h10 = h[p + 1], h01 = h[p + width], h11 = h[p + width + 1];
      const float lo = fmin(fmin(h00, h10), fmin(h01, h11)), hi = fmax(fmax(h00, h10), fmax(h01, h11));
      const float below = lo - fmax(1.0f, fabs(lo) * 0x1p-20f),
                  above = hi + band_hi + fmax(1.0f, fabs(hi) * 0x1p-20f);
      const float cut = dz < 0.0f ? (oz - below) / -dz : (dz > 0.0f ? (above - oz) / dz : 0.0f);
      // (fmin and fmax pass over a NaN corner: any NaN corner leaves the cell without surface)
      if (!isnan(h00 + h10 + h01 + h11) && cut < INFINITY) t_end = cut > 0.0f ? cut : 0.0f;
    }
  }
  const float t = hf_ray_cast_within(h, width, height, pyramid, levels, top, ox, oy, oz, dx, dy, dz, t_end,
                                     curvature, cell_x, cell_y, view, view_x, band_lo, band_hi, cap, pierced,
                                     pierced_t, stride, count, cell);
  return *cell < 0 && t_end != t_max ? t_max : t;
}

#endif  // HFVIS_HEIGHTFIELD_RAY_CL
