// region_visibility_sight.cl: the line-of-sight test between two arbitrary points over the
// bilinear surface, and the stratified, jittered sample positions of a region (hfvis/
// region_visibility.hpp). Written once in the common subset of OpenCL C and C++:
// kernels/region_visibility.cl includes it, and so does src/ops/region_visibility_sight.hpp (inside
// namespace hfvis::detail), so the kernel and the scalar reference run the very same float
// operations and agree bit for bit (no contraction into fma on either side, no math library
// call but the correctly rounded division).
//
// The test is the viewshed's (kernels/viewshed.cl, sight_walk): the surface along a segment
// is a quadratic within each cell, so the segment is decided from the values at the grid-line
// crossings and, inside each cell, the top of the quadratic. It differs in three ways, each for
// the region contract: the end points are any points of the field, not grid points; the pair is
// put in a canonical order first, so that the answer from A to B is the answer from B to A
// bit for bit (a float march rounds differently from its two ends); and the curvature is taken
// in its symmetric form c D^2 t (1 - t) (the sight line's rise over the surface lowered by
// c (t D)^2 from one end, which is the same function from either end).
#ifndef HFVIS_REGION_SIGHT_CL
#define HFVIS_REGION_SIGHT_CL

#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
#define HFVIS_GLOBAL __global
// The march and the hiding-cell test inlined where the kernels call them (each from a few
// places in a word's loop): 2 - 6 % less CPU time on the CPU device's region pairs
// (bench/report/region_visibility.md); the C++ reference leaves it to the compiler.
#define HFVIS_SIGHT_INLINE inline __attribute__((always_inline))
#else
#define HFVIS_GLOBAL
#define HFVIS_SIGHT_INLINE inline
#endif

// The surface on the column line x = cx (an integer) at row coordinate y: the interpolation
// between the line's two heights around y, or the height itself at a grid point, so that a
// point of an edge between two valid heights is surface beside a nodata cell too.
inline float region_column_value(HFVIS_GLOBAL const float* h, int width, int height, int cx, float y) {
  const int cy = (int)y < height - 1 ? (int)y : height - 1;
  const float v = y - (float)cy;
  const float h0 = h[cy * width + cx];
  if (v == 0.0f) return h0;
  const float h1 = h[(cy + 1) * width + cx];
  return h0 + (h1 - h0) * v;
}

// The bilinear surface at (x, y), clamped into the field: NaN where it takes a nodata height
// (a point on an edge or a grid point takes only the heights of that edge or point).
inline float region_surface_at(HFVIS_GLOBAL const float* h, int width, int height, float x, float y) {
  x = x < 0.0f ? 0.0f : (x > (float)(width - 1) ? (float)(width - 1) : x);
  y = y < 0.0f ? 0.0f : (y > (float)(height - 1) ? (float)(height - 1) : y);
  const int cx = (int)x < width - 1 ? (int)x : width - 1;  // x >= 0: truncation is floor
  const float u = x - (float)cx;
  const float a = region_column_value(h, width, height, cx, y);
  if (u == 0.0f) return a;
  const float b = region_column_value(h, width, height, cx + 1, y);
  return a + (b - a) * u;
}

// How much the surface changes per pixel along a grid line (`on_column`: the column line x =
// `line`, else the row line y = `line`) at coordinate `at` along it: |the difference of the edge's
// two heights|, the larger of the two edges' where `at` is a grid point. A crossing's position
// along its line rounds (region_position_reach); this is what a pixel of it costs. A number
// always (nodata and infinite heights count 0).
inline float region_crossing_slope(HFVIS_GLOBAL const float* h, int width, int height, int on_column,
                                   float line, float at) {
  const int n = on_column ? height : width, step = on_column ? width : 1;
  if (n < 2) return 0.0f;
  at = at < 0.0f ? 0.0f : (at > (float)(n - 1) ? (float)(n - 1) : at);
  const int k = (int)at < n - 2 ? (int)at : n - 2;
  const int base = on_column ? (int)line : (int)line * width;
  HFVIS_GLOBAL const float* e = h + base + k * step;
  // (an infinite height: the value there is infinite or NaN, and forgives nothing more)
  const float own = fabs(e[step] - e[0]);
  float slope = isfinite(own) ? own : 0.0f;
  const float before = at == (float)k && k > 0 ? fabs(e[0] - e[-step]) : 0.0f;
  const float after = at == (float)(k + 1) && k + 2 < n ? fabs(e[2 * step] - e[step]) : 0.0f;
  if (isfinite(before)) slope = fmax(slope, before);
  if (isfinite(after)) slope = fmax(slope, after);
  return slope;
}

// The twist h00 - h10 - h01 + h11 of the cell under (x, y) (clamped to the field; a field one
// pixel wide or high has none): the t^2 coefficient of the surface along a segment of steps
// (dx, dy) through it is twist dx dy. NaN where a corner is nodata.
inline float region_cell_twist(HFVIS_GLOBAL const float* h, int width, int height, float x, float y) {
  if (width < 2 || height < 2) return 0.0f;
  int cx = (int)(x < 0.0f ? 0.0f : x), cy = (int)(y < 0.0f ? 0.0f : y);
  cx = cx > width - 2 ? width - 2 : cx;
  cy = cy > height - 2 ? height - 2 : cy;
  const int p = cy * width + cx;
  return h[p] - h[p + 1] - h[p + width] + h[p + width + 1];
}

// The segment's height above the surface at t, negated: f(t) = s(t) - (za + t (zb - za)) +
// c D^2 t (1 - t), s the surface at the point over t (given).
inline float region_rise(float s, float t, float za, float dz, float cdd) {
  return (s - (za + t * dz)) + cdd * t * (1.0f - t);
}

// How far the surface may rise above a segment from height za to zb (cdd: c D^2, the curvature's
// term) and still not hide it: the heights' rounding, which grazing lines forgive as the tie rule
// of `viewcount` does (docs/ALGORITHMS.md, "Grazing samples and the heights' rounding"). A float32
// raster holds each height to the float's spacing at its absolute value, and the march's values
// round again by a few units in the last place; on a tilted plane a segment between two points of
// the surface runs along it, and an exact sign hid nearly every such pair (a plane at 8848 m: all
// of them). 2^-21 of |za| + |zb| + |cdd|: about 8 units in the last place of the larger end's
// height, no more (a wall of a dozen units in the last place still hides).
inline float region_forgiven(float za, float zb, float cdd) {
  return 0x1p-21f * (fabs(za) + fabs(zb) + fabs(cdd));
}

// The march also rounds the positions of the segment's grid crossings, by a few units in the last
// place of the coordinates (pixels from the field's corner): the surface there rounds by that
// times its slope, which the heights do not bound (a plane h = x - 200 holds heights near 0 at
// x = 200, where the rounding of x is 1.5e-5; it hid nearly every pair there). A crossing forgives
// its surface's slope along its line (region_crossing_slope) times this reach: 2^-21 of the
// largest |x| + the largest |y| of the segment's ends, plus 2 (pixels).
inline float region_position_reach(float xa, float ya, float xb, float yb) {
  return 0x1p-21f * (fmax(fabs(xa), fabs(xb)) + fmax(fabs(ya), fabs(yb)) + 2.0f);
}

// The culling pyramid (a max pyramid over the cells): level k holds, per block of 2^k x 2^k cells
// (the last ones in a row or column cut by the field), the highest point of the surface over the
// block's closed square, +INFINITY where the march's values there can run unbounded (an infinite
// height in or beside the block), -INFINITY where it has no surface; levels are stored one after
// another, rows of region_cull_width blocks.
inline int region_cull_width(int width, int k) { return ((width - 1) + (1 << k) - 1) >> k; }

inline int region_cull_offset(int width, int height, int k) {
  int offset = 0;
  for (int j = 0; j < k; ++j) offset += region_cull_width(width, j) * region_cull_width(height, j);
  return offset;
}

// The first grid line (an integer of the coordinate from `a` in steps of `d`) whose crossing
// parameter (line - a) / d, as the march computes it, comes after t (`at_too`: at or after t).
inline float region_cull_next_line(float a, float d, float t, int at_too) {
  float g = d > 0.0f ? floor(a + t * d) : ceil(a + t * d);
  const float step = d > 0.0f ? 1.0f : -1.0f;
  // Forward past the lines before t, then back over lines still after it (never behind a).
  for (;;) {
    const float tg = (g - a) / d;
    if (at_too ? tg >= t : tg > t) break;
    g += step;
  }
  for (;;) {
    const float back = g - step;
    if (!(d > 0.0f ? back > a : back < a)) break;
    const float tb = (back - a) / d;
    if (!(at_too ? tb >= t : tb > t)) break;
    g = back;
  }
  return g;
}

// Resumes a march (region_sight_visible_culled) at the crossing C = tC of the segment from
// (xa, ya) by (dx, dy) with the column line lx (`on_column`) or the row line ly: the march's next
// column line becomes the first after C, its next row line the first at or after C (x first on a
// tie, as the march orders them).
inline void region_cull_resume(float xa, float ya, float dx, float dy, int on_column, float lx, float ly,
                               float tC, float* gxl, float* gyl) {
  if (on_column) {
    *gxl = lx + 1.0f;
    if (dy != 0.0f) *gyl = region_cull_next_line(ya, dy, tC, 1);
  } else {
    *gyl = dy > 0.0f ? ly + 1.0f : ly - 1.0f;
    if (dx > 0.0f) *gxl = region_cull_next_line(xa, dx, tC, 0);
  }
}

// The march's value (region_rise) at that crossing; *at: the crossing's position along its line.
inline float region_cull_crossing_rise(HFVIS_GLOBAL const float* h, int width, int height, float xa, float ya,
                                       float za, float dx, float dy, float dz, float cdd, int on_column,
                                       float lx, float ly, float tC, float* at) {
  *at = on_column ? ya + tC * dy : xa + tC * dx;
  const float s =
      on_column ? region_surface_at(h, width, height, lx, *at) : region_surface_at(h, width, height, *at, ly);
  return region_rise(s, tC, za, dz, cdd);
}

// A crossing as the march keeps it, for its slope (region_crossing_slope), which is looked up only
// where its value passes the heights' rounding (rarely: not on a line clear there): on the column
// line (`on_column` 1) or the row line (0) `line` at `at` along it; on_column -1: an end of the
// segment, whose position is given, not rounded (slope 0).
typedef struct {
  int on_column;
  float line, at;
} RegionCrossing;

inline float region_slope_of(HFVIS_GLOBAL const float* h, int width, int height, RegionCrossing c) {
  return c.on_column < 0 ? 0.0f : region_crossing_slope(h, width, height, c.on_column, c.line, c.at);
}

// The index of the first corner of the cell under (x, y), clamped into the field (for
// region_cull_hides).
inline int region_cell_at(int width, int height, float x, float y) {
  int cx = (int)(x < 0.0f ? 0.0f : x), cy = (int)(y < 0.0f ? 0.0f : y);
  cx = cx > width - 2 ? width - 2 : cx;
  cy = cy > height - 2 ? height - 2 : cy;
  return cx < 0 || cy < 0 ? -1 : cy * width + cx;
}

// Whether the point (xb, yb, zb) is visible from (xa, ya, za) (pixel positions inside the field,
// heights z-scaled and finite): 1 when no point of the surface strictly between them rises
// above the segment by more than the heights' rounding (region_forgiven, and at a grid crossing the
// rounding of its position, region_position_reach; an end below the surface
// by more counts: the surface rises above the segment right beside it), the surface lowered by the curvature
// (cell_x, cell_y: ground units per pixel; curvature: c of a drop c d^2; max_d2: the largest squared ground
// distance seen, 0 = any). A cell with a nodata corner has no surface inside; an edge or grid point between
// valid heights is surface. Pieces shorter than 1e-3 pixel skip their inside test, as the viewshed's do
// (their top would be rounding noise).
//
// With a culling pyramid (`levels` > 0: region_cull_* below), the march leaps over every block of
// cells that provably cannot reach the segment: it resumes at the crossing where the segment leaves
// the block, in the state the step-by-step march would have there, so that the answer is the same
// bit for bit, only sooner.
HFVIS_SIGHT_INLINE int region_sight_visible_culled(HFVIS_GLOBAL const float* h, int width, int height,
                                                   float cell_x, float cell_y, float curvature, float max_d2,
                                                   HFVIS_GLOBAL const float* pyramid, int levels,
                                                   float margin, float box_x0, float box_y0, float box_x1,
                                                   float box_y1, float xa, float ya, float za, float xb,
                                                   float yb, float zb, float reach_a, float reach_b,
                                                   int* blocked_at) {
  // The canonical order: from the smaller end in (x, y, z), so that the test is symmetric.
  if (xb < xa || (xb == xa && (yb < ya || (yb == ya && zb < za)))) {
    float s = reach_a;
    reach_a = reach_b, reach_b = s;
    s = xa;
    xa = xb, xb = s;
    s = ya;
    ya = yb, yb = s;
    s = za;
    za = zb, zb = s;
  }
  const float dx = xb - xa, dy = yb - ya, dz = zb - za;  // dx >= 0
  if (dx == 0.0f && dy == 0.0f) return 1;
  const float gx = dx * cell_x, gy = dy * cell_y;
  const float d2 = gx * gx + gy * gy;
  if (max_d2 > 0.0f && d2 > max_d2) return 0;
  const float cdd = curvature * d2;
  const float forgiven = region_forgiven(za, zb, cdd);
  // (and at each crossing the surface's slope there times `reach`: c0 is f0's crossing, c1 f1's)
  const float reach = region_position_reach(xa, ya, xb, yb);
  RegionCrossing c0 = {-1, 0.0f, 0.0f}, c1 = {-1, 0.0f, 0.0f};
  const float pixels = dx > (dy < 0.0f ? -dy : dy) ? dx : (dy < 0.0f ? -dy : dy);
  // The ends' certified stretches (region_end_reach) meet: no cell along the segment comes near it.
  const float length = reach_a > 0.0f || reach_b > 0.0f ? sqrt(dx * dx + dy * dy) : 0.0f;
  if (length > 0.0f && reach_a + reach_b >= length) return 1;
  // On a grid line the surface is that edge's straight line, beside a nodata cell too.
  const int on_grid_line = (dx == 0.0f && xa == (float)(int)xa) || (dy == 0.0f && ya == (float)(int)ya);
  // The next column line after xa and the next row line after ya (toward yb).
  float gxl = (float)((int)xa + 1);
  float gyl = dy > 0.0f ? (float)((int)ya + 1) : ((float)(int)ya == ya ? ya - 1.0f : (float)(int)ya);
  float t0 = 0.0f;
  // An end below the surface has surface above the segment right beside it (the viewshed's
  // eye below its own ground sees nothing).
  float f0 = region_surface_at(h, width, height, xa, ya) - za;
  if (f0 > forgiven) return 0;
  // The culling: the clearance a block must leave below the segment (the rounding of the march's
  // values: `margin`, the field's part from the host's cullPyramid, and the segment's; and the
  // curvature's largest rise c D^2 / 4), and the level tried next (one up after a leap, down to
  // the cell after a refusal).
  const float clearance =
      margin + 1e-5f * (2.0f * (fabs(za) + fabs(zb)) + fabs(cdd)) + (cdd > 0.0f ? 0.25f * cdd : 0.0f);
  int level = 0;
  // After a leap: the crossing where it ended, its value f0 not yet taken.
  int pending = 0, pending_on_column = 0;
  float pending_lx = 0.0f, pending_ly = 0.0f;
  // Each level's offset and row width in the pyramid (levels <= 16, the host's kCullLevels).
  int level_offset[16], level_width[16];
  for (int k = 0, offset = 0; k < levels; ++k) {
    level_offset[k] = offset;
    level_width[k] = region_cull_width(width, k);
    offset += level_width[k] * region_cull_width(height, k);
  }
  // Outside the box of grid lines (box_x0 <= x <= box_x1, box_y0 <= y <= box_y1; none when
  // box_x0 > box_x1), which holds one end, the caller has shown the segment clear by the same
  // margins: the march starts where the segment enters the box and ends where it leaves.
  float t_out = INFINITY;
  if (box_x0 <= box_x1) {
    if (xa < box_x0 || xa > box_x1 || ya < box_y0 || ya > box_y1) {
      const float tX = xa < box_x0 ? (box_x0 - xa) / dx : -INFINITY;
      const float ly = dy > 0.0f ? box_y0 : box_y1;
      const float tY = (dy > 0.0f && ya < box_y0) || (dy < 0.0f && ya > box_y1) ? (ly - ya) / dy : -INFINITY;
      const int on_column = tX >= tY;
      const float tC = on_column ? tX : tY;
      if (tC > 0.0f && tC < 1.0f) {
        t0 = tC;
        region_cull_resume(xa, ya, dx, dy, on_column, box_x0, ly, tC, &gxl, &gyl);
        f0 = region_cull_crossing_rise(h, width, height, xa, ya, za, dx, dy, dz, cdd, on_column, box_x0, ly,
                                       tC, &c0.at);
        c0.on_column = on_column, c0.line = on_column ? box_x0 : ly;
        if (f0 > forgiven && f0 > forgiven + reach * region_slope_of(h, width, height, c0)) return 0;
      }
    }
    const float tX = xb > box_x1 ? (box_x1 - xa) / dx : INFINITY;
    const float tY = dy > 0.0f && yb > box_y1 ? (box_y1 - ya) / dy
                                              : (dy < 0.0f && yb < box_y0 ? (box_y0 - ya) / dy : INFINITY);
    t_out = tX < tY ? tX : tY;
  }
  // The stretches the ends' tables certified (reach_a from a, reach_b from b, in pixels): the march
  // starts at the last grid crossing within a's (a crossing of the march's own, in its own state,
  // as after a leap) and ends where b's begins; every cell of the segment outside lies below it
  // by the march's clearance, so the march would have leapt it (region_end_reach). The 0.01 pixel
  // taken off each covers the rounding of the stretches' parameters.
  if (reach_a > 0.01f) {
    const float t_in = (reach_a - 0.01f) / length;
    // The last column line and the last row line crossed at or before t_in, after a.
    const float lx = dx > 0.0f ? region_cull_next_line(xa, dx, t_in, 0) - 1.0f : xa;
    const float ly = dy > 0.0f ? region_cull_next_line(ya, dy, t_in, 0) - 1.0f
                               : (dy < 0.0f ? region_cull_next_line(ya, dy, t_in, 0) + 1.0f : ya);
    const float tX = lx > xa ? (lx - xa) / dx : -INFINITY;
    const float tY = (dy > 0.0f && ly > ya) || (dy < 0.0f && ly < ya) ? (ly - ya) / dy : -INFINITY;
    const int on_column = tX >= tY;
    const float tC = on_column ? tX : tY;
    if (tC > t0 && tC < 1.0f) {
      t0 = tC;
      region_cull_resume(xa, ya, dx, dy, on_column, lx, ly, tC, &gxl, &gyl);
      f0 = region_cull_crossing_rise(h, width, height, xa, ya, za, dx, dy, dz, cdd, on_column, lx, ly, tC,
                                     &c0.at);
      c0.on_column = on_column, c0.line = on_column ? lx : ly;
      if (f0 > forgiven && f0 > forgiven + reach * region_slope_of(h, width, height, c0)) return 0;
    }
  }
  if (reach_b > 0.01f) {
    const float t_end = 1.0f - (reach_b - 0.01f) / length;
    t_out = t_out < t_end ? t_out : t_end;
  }
  for (;;) {
    if (t0 >= t_out) return 1;
    // The next crossings (after a leap, once its resumption is taken).
    float tx = 0.0f, ty = 0.0f;
    if (!pending) {
      tx = dx > 0.0f && gxl < xb ? (gxl - xa) / dx : INFINITY;
      ty = dy > 0.0f ? (gyl < yb ? (gyl - ya) / dy : INFINITY)
                     : (dy < 0.0f && gyl > yb ? (gyl - ya) / dy : INFINITY);
    }
    if (levels > 0) {
      // The cell of the next piece (its middle; after a leap, the cell beyond the crossing where it
      // ended), and the blocks above it from `level` down.
      int cx, cy;
      if (pending) {
        const float beyond = pending_on_column ? ya + t0 * dy : xa + t0 * dx;
        if (pending_on_column) {
          cx = (int)pending_lx;
          cy = (int)(dy < 0.0f ? ceil(beyond) - 1.0f : floor(beyond));
        } else {
          cx = (int)floor(beyond);
          cy = dy > 0.0f ? (int)pending_ly : (int)pending_ly - 1;
        }
      } else {
        const float tn = tx < ty ? (tx < 1.0f ? tx : 1.0f) : (ty < 1.0f ? ty : 1.0f), tm = 0.5f * (t0 + tn);
        cx = (int)(xa + tm * dx), cy = (int)(ya + tm * dy);
      }
      cx = cx < 0 ? 0 : (cx > width - 2 ? width - 2 : cx);
      cy = cy < 0 ? 0 : (cy > height - 2 ? height - 2 : cy);
      int leapt = 0;
      for (int k = level; k >= 0 && !leapt; --k) {
        const int bx = cx >> k, by = cy >> k;
        const float top = pyramid[level_offset[k] + by * level_width[k] + bx];
        // Where the segment leaves the block: its column line on the right or its row line ahead,
        // each crossing's parameter as the march computes it.
        const int right = (bx + 1) << k, ahead = dy > 0.0f ? (by + 1) << k : by << k;
        const float lx = (float)(right < width - 1 ? right : width - 1);
        const float ly = (float)(dy > 0.0f ? (ahead < height - 1 ? ahead : height - 1) : ahead);
        const float tX = dx > 0.0f && lx < xb ? (lx - xa) / dx : INFINITY;
        const float tY = dy > 0.0f ? (ly < yb ? (ly - ya) / dy : INFINITY)
                                   : (dy < 0.0f && ly > yb ? (ly - ya) / dy : INFINITY);
        const int leave_x = tX <= tY;
        // (past t_out the caller has shown the segment clear: the block need clear it up to there)
        const float tL = t_out < 1.0f ? t_out : 1.0f;
        const float tC = leave_x ? tX : tY, tE = tC < tL ? tC : tL;
        const float z0 = za + t0 * dz, zE = za + tE * dz;
        if (!(tE > t0 && top + clearance < (z0 < zE ? z0 : zE))) continue;
        if (tC >= tL) return 1;  // the block holds the rest of the segment (to t_out), its end too
        // Resume at the crossing C where the segment leaves: the march's state there waits for the
        // next step that needs it (a run of leaps needs none: each block proved itself below the
        // segment, its crossings too).
        t0 = tC;
        pending = 1, pending_on_column = leave_x, pending_lx = lx, pending_ly = ly;
        level = k + 1 < levels ? k + 1 : k;
        leapt = 1;
      }
      if (leapt) continue;
      level = 0;
      if (pending) {
        region_cull_resume(xa, ya, dx, dy, pending_on_column, pending_lx, pending_ly, t0, &gxl, &gyl);
        f0 = region_cull_crossing_rise(h, width, height, xa, ya, za, dx, dy, dz, cdd, pending_on_column,
                                       pending_lx, pending_ly, t0, &c0.at);
        c0.on_column = pending_on_column, c0.line = pending_on_column ? pending_lx : pending_ly;
        if (f0 > forgiven && f0 > forgiven + reach * region_slope_of(h, width, height, c0)) return 0;
        pending = 0;
        tx = dx > 0.0f && gxl < xb ? (gxl - xa) / dx : INFINITY;
        ty = dy > 0.0f ? (gyl < yb ? (gyl - ya) / dy : INFINITY)
                       : (dy < 0.0f && gyl > yb ? (gyl - ya) / dy : INFINITY);
      }
    }
    const int x_first = tx <= ty;
    float t1 = x_first ? tx : ty;
    float f1;
    if (t1 >= 1.0f) {  // no crossing left before the far end
      t1 = 1.0f;
      f1 = region_surface_at(h, width, height, xb, yb) - zb;
      c1.on_column = -1;
      if (f1 > forgiven) return 0;
    } else {
      // A crossing: on a column line x = gxl exactly, or on a row line y = gyl.
      c1.on_column = x_first, c1.line = x_first ? gxl : gyl, c1.at = x_first ? ya + t1 * dy : xa + t1 * dx;
      const float s = x_first ? region_surface_at(h, width, height, gxl, c1.at)
                              : region_surface_at(h, width, height, c1.at, gyl);
      f1 = region_rise(s, t1, za, dz, cdd);
      if (f1 > forgiven &&
          f1 > forgiven + reach * region_slope_of(h, width, height, c1)) {  // NaN hides nothing
        *blocked_at = region_cell_at(width, height, xa + 0.5f * (t0 + t1) * dx, ya + 0.5f * (t0 + t1) * dy);
        return 0;
      }
    }
    const float span = t1 - t0;
    if (span > 0.0f && span * pixels > 1e-3f && !isnan(f0) && !isnan(f1)) {
      const float tm = 0.5f * (t0 + t1);
      const float twist = region_cell_twist(h, width, height, xa + tm * dx, ya + tm * dy);
      if (!isnan(twist) || on_grid_line) {
        // f over the piece in its own parameter s: f0 + (f1 - f0) s + bump s (1 - s).
        const float bump = -((dx * dy != 0.0f ? twist * dx * dy : 0.0f) - cdd) * span * span;
        if (bump > 0.0f) {
          const float s = 0.5f + (f1 - f0) / (2.0f * bump);
          const float top = f0 + (f1 - f0) * s + bump * s * (1.0f - s);
          if (s > 0.0f && s < 1.0f && top > forgiven &&
              top > forgiven + reach * fmax(region_slope_of(h, width, height, c0),
                                            region_slope_of(h, width, height, c1))) {
            *blocked_at = region_cell_at(width, height, xa + tm * dx, ya + tm * dy);
            return 0;
          }
        }
      }
    }
    if (t1 == 1.0f) return 1;
    if (x_first)
      gxl += 1.0f;
    else
      gyl += dy > 0.0f ? 1.0f : -1.0f;
    t0 = t1;
    f0 = f1;
    c0 = c1;
  }
}

// The march without culling (the exact method and the scalar reference).
inline int region_sight_visible(HFVIS_GLOBAL const float* h, int width, int height, float cell_x,
                                float cell_y, float curvature, float max_d2, float xa, float ya, float za,
                                float xb, float yb, float zb) {
  int blocked_at;
  return region_sight_visible_culled(h, width, height, cell_x, cell_y, curvature, max_d2, h, 0, 0.0f, 1.0f,
                                     0.0f, 0.0f, 0.0f, xa, ya, za, xb, yb, zb, 0.0f, 0.0f, &blocked_at);
}

// Per-end tables of headroom (the certification of the culled march's clear sight lines): for an
// end point E of many sight lines (a sample, a receiver) and the rectangle where their other ends
// lie, the highest pyramid value (region_cull_*: a cell's highest corner, +INFINITY where the
// march's values are unbounded, -INFINITY over no surface) over every cell that can meet a segment
// from E, by direction wedge and radial band: REGION_END_BANDS bands [0, 1], [1, 2], ... [7, 8],
// then four to an octave ([8, 10], [10, 12], [12, 14], [14, 16], [16, 20], ...: region_band_edge)
// and REGION_END_WEDGES wedges of the cone of directions from E toward the rectangle (all
// directions where E lies at or near it). Directions are pseudo-angles (region_pseudo_angle: a
// monotone stand-in for the angle, 0 .. 4 a turn, one division). A line from E of slope s (height
// per pixel) clears band b when the band's value plus the clearance lies below its lowest point
// over the band, E's height plus s times the band's inner radius (s >= 0) or its outer one (s < 0):
// when s exceeds the band's required slope (value + clearance - E's height) / radius. The record
// keeps per wedge the running maxima of the bands' required slopes from E outward, for rising and
// for falling lines, so that a line's certified bands are those whose running maximum lies below
// its slope (region_end_reach: a count). A record: the cone's first pseudo-angle, its span, the
// bands filled, 0, then per wedge the rising maxima and the falling ones, REGION_END_BANDS each.
#define REGION_END_WEDGES 8
#define REGION_END_BANDS 40
#define REGION_END_RECORD (4 + 2 * REGION_END_WEDGES * REGION_END_BANDS)

// The bands' radii, whole pixels: 0 .. 8, then 8, 10, 12, 14 times powers of 2 (up to 2048): bands
// at most a quarter as wide as their inner radius, since a rising line is held to its slope at the
// band's inner radius and a falling one at its outer (finer bands certify more clear lines whole
// than doubling ones: bench/report/region_visibility.md).
inline float region_band_edge(int b) {
  return b <= 8 ? (float)b : (float)((8 + 2 * ((b - 8) & 3)) << ((b - 8) >> 2));
}

// The pseudo-angle of the direction (x, y): 0 .. 4 counter-clockwise from +x, 1 per quarter turn,
// p(-x, -y) = p(x, y) + 2 (mod 4).
inline float region_pseudo_angle(float x, float y) {
  if (y >= 0.0f) return x >= 0.0f ? (x + y > 0.0f ? y / (x + y) : 0.0f) : 1.0f - x / (y - x);
  return x < 0.0f ? 2.0f - y / (-x - y) : 3.0f + x / (x - y);
}

// A pseudo-angle difference into [0, 4).
inline float region_turn(float d) {
  d -= 4.0f * floor(0.25f * d);
  return d < 4.0f ? d : 0.0f;
}

// The unit direction of pseudo-angle p (0 <= p < 4), for the table's bounding boxes.
inline void region_pseudo_direction(float p, float* x, float* y) {
  float u, v;
  if (p < 1.0f)
    u = 1.0f - p, v = p;
  else if (p < 2.0f)
    u = 1.0f - p, v = 2.0f - p;
  else if (p < 3.0f)
    u = p - 3.0f, v = 2.0f - p;
  else
    u = p - 3.0f, v = p - 4.0f;
  const float n = sqrt(u * u + v * v);
  *x = u / n, *y = v / n;
}

// The wedge of the direction (x, y) in a record, -1 outside its cone.
inline int region_end_wedge(float first, float span, float x, float y) {
  const float u = region_turn(region_pseudo_angle(x, y) - first) * ((float)REGION_END_WEDGES / span);
  const int w = (int)u;
  if (span >= 4.0f) return w < REGION_END_WEDGES ? w : REGION_END_WEDGES - 1;
  return w < REGION_END_WEDGES ? w : -1;
}

// Fills the record (rec: REGION_END_RECORD floats) of E = (ex, ey, ez) over the pyramid (`levels` >
// 0) for the other ends in the rectangle (ox0, oy0) .. (ox1, oy1), their heights within +-z_bound.
// Conservative throughout: a band is looked at in blocks of the pyramid (at most a quarter of its
// inner radius a side, cells up to radius 8), and a block counts for every wedge and band its box,
// grown by 0.01 pixel, meets in the box's ranges of distance and pseudo-angle from E (which hold the
// box's own), the cone and the wedges grown by 1e-4 (the look-up's and the box corners'
// roundings); a box holding E counts for every wedge. The clearance is region_end_clearance's for
// the longest line toward the rectangle and both ends' heights at their bound.
inline void region_end_table(HFVIS_GLOBAL const float* pyramid, int levels, int width, int height,
                             float margin, float curvature, float cell_x, float cell_y, float ex, float ey,
                             float ez, float z_bound, float ox0, float oy0, float ox1, float oy1,
                             HFVIS_GLOBAL float* rec) {
  const float grow = 0.01f, turn_grow = 1e-4f;
  float first = 0.0f, span = 4.0f, far2 = 0.0f;
  for (int c = 0; c < 4; ++c) {
    const float vx = (c & 1 ? ox1 : ox0) - ex, vy = (c & 2 ? oy1 : oy0) - ey;
    far2 = fmax(far2, vx * vx + vy * vy);
  }
  if (ex < ox0 - 0.5f || ex > ox1 + 0.5f || ey < oy0 - 0.5f || ey > oy1 + 0.5f) {
    // E outside the rectangle: the corners' pseudo-angles about the centre's hold the cone.
    const float mid = region_pseudo_angle(0.5f * (ox0 + ox1) - ex, 0.5f * (oy0 + oy1) - ey);
    float lo = 0.0f, hi = 0.0f;
    for (int c = 0; c < 4; ++c) {
      float d = region_pseudo_angle((c & 1 ? ox1 : ox0) - ex, (c & 2 ? oy1 : oy0) - ey) - mid;
      d = d > 2.0f ? d - 4.0f : (d <= -2.0f ? d + 4.0f : d);
      lo = fmin(lo, d), hi = fmax(hi, d);
    }
    if (hi - lo + 2.0f * turn_grow < 2.0f)
      first = region_turn(mid + lo - turn_grow), span = hi - lo + 2.0f * turn_grow;
  }
  int bands = 1;
  while (bands < REGION_END_BANDS && region_band_edge(bands) * region_band_edge(bands) < far2) ++bands;
  rec[0] = first, rec[1] = span, rec[2] = (float)bands, rec[3] = 0.0f;
  // The clearance (for the longest line and both ends' heights at their bound), known before the
  // bands, so that each band's required slopes follow from its values at once: only the band's
  // values and the running maxima (3 * REGION_END_WEDGES floats) are kept, the record is written
  // band by band (a private copy of the whole record, REGION_END_RECORD = 644 floats, would spill
  // from a GPU's registers).
  const float cell = fmax(cell_x, cell_y), cdd = curvature * far2 * cell * cell;
  const float clearance =
      margin + 1e-5f * (4.0f * (fabs(ez) + z_bound) + fabs(cdd)) + (cdd > 0.0f ? 0.25f * cdd : 0.0f);
  float value[REGION_END_WEDGES], up_max[REGION_END_WEDGES], down_max[REGION_END_WEDGES];
  for (int w = 0; w < REGION_END_WEDGES; ++w) up_max[w] = down_max[w] = -INFINITY;
  // The unit directions of the cone's edges, for the bands' bounding boxes.
  float ux0, uy0, ux1, uy1;
  region_pseudo_direction(first, &ux0, &uy0);
  region_pseudo_direction(region_turn(first + span), &ux1, &uy1);
  for (int b = 0; b < bands; ++b) {
    const float r0 = region_band_edge(b), r1 = region_band_edge(b + 1);
    for (int w = 0; w < REGION_END_WEDGES; ++w) value[w] = -INFINITY;
    int k = 0;
    while (k + 1 < levels && (float)(8 << k) <= r0) ++k;
    // The band's box: the cone's edges at both radii, and the axis directions within it at r1.
    float x0 = ex - r1, x1 = ex + r1, y0 = ey - r1, y1 = ey + r1;
    if (span < 4.0f) {
      x0 = fmin(fmin(ex + r0 * ux0, ex + r1 * ux0), fmin(ex + r0 * ux1, ex + r1 * ux1));
      x1 = fmax(fmax(ex + r0 * ux0, ex + r1 * ux0), fmax(ex + r0 * ux1, ex + r1 * ux1));
      y0 = fmin(fmin(ey + r0 * uy0, ey + r1 * uy0), fmin(ey + r0 * uy1, ey + r1 * uy1));
      y1 = fmax(fmax(ey + r0 * uy0, ey + r1 * uy0), fmax(ey + r0 * uy1, ey + r1 * uy1));
      for (int q = 0; q < 4; ++q)
        if (region_turn((float)q - first) <= span) {
          if (q == 0) x1 = fmax(x1, ex + r1);
          if (q == 1) y1 = fmax(y1, ey + r1);
          if (q == 2) x0 = fmin(x0, ex - r1);
          if (q == 3) y0 = fmin(y0, ey - r1);
        }
    }
    const float pad = grow + 1e-4f * r1;
    x0 -= pad, y0 -= pad, x1 += pad, y1 += pad;
    const int kw = region_cull_width(width, k), kh = region_cull_width(height, k);
    const int offset = region_cull_offset(width, height, k);
    const float size = (float)(1 << k);
    int bx0 = (int)floor(x0 / size), bx1 = (int)floor(x1 / size);
    int by0 = (int)floor(y0 / size), by1 = (int)floor(y1 / size);
    bx0 = bx0 < 0 ? 0 : bx0, by0 = by0 < 0 ? 0 : by0;
    bx1 = bx1 < kw - 1 ? bx1 : kw - 1, by1 = by1 < kh - 1 ? by1 : kh - 1;
    for (int by = by0; by <= by1; ++by)
      for (int bx = bx0; bx <= bx1; ++bx) {
        const float X0 = (float)bx * size - grow - ex, Y0 = (float)by * size - grow - ey;
        const float X1 = fmin((float)(bx + 1) * size, (float)(width - 1)) + grow - ex;
        const float Y1 = fmin((float)(by + 1) * size, (float)(height - 1)) + grow - ey;
        const float nx = fmax(0.0f, fmax(X0, -X1)), ny = fmax(0.0f, fmax(Y0, -Y1));
        const float fx = fmax(-X0, X1), fy = fmax(-Y0, Y1);
        if (nx * nx + ny * ny > r1 * r1 || fx * fx + fy * fy < r0 * r0) continue;
        const float top = pyramid[offset + by * kw + bx];
        float lo = 0.0f, hi = 4.0f;  // the box's pseudo-angles from the cone's first
        if (nx > 0.0f || ny > 0.0f) {
          // (about the first corner's: the box seen from outside spans less than half a turn)
          const float mid = region_pseudo_angle(X0, Y0);
          float dlo = 0.0f, dhi = 0.0f;
          for (int c = 1; c < 4; ++c) {
            float d = region_pseudo_angle(c & 1 ? X1 : X0, c & 2 ? Y1 : Y0) - mid;
            d = d > 2.0f ? d - 4.0f : (d <= -2.0f ? d + 4.0f : d);
            dlo = fmin(dlo, d), dhi = fmax(dhi, d);
          }
          lo = region_turn(mid + dlo - first - turn_grow);
          hi = lo + (dhi - dlo) + 2.0f * turn_grow;
        }
        // The wedges of [lo, hi] and of its part past a full turn, within the cone.
        for (int part = 0; part < 2; ++part) {
          const float a = part ? lo - 4.0f : lo, z = part ? hi - 4.0f : hi;
          if (z < 0.0f || a > span) continue;
          const int w0 = (int)(fmax(a, 0.0f) * ((float)REGION_END_WEDGES / span));
          int w1 = (int)(fmin(z, span) * ((float)REGION_END_WEDGES / span));
          w1 = w1 < REGION_END_WEDGES - 1 ? w1 : REGION_END_WEDGES - 1;
          for (int w = w0; w <= w1; ++w) value[w] = fmax(value[w], top);
        }
      }
    for (int w = 0; w < REGION_END_WEDGES; ++w) {
      // (a band's value is finite or infinite, never NaN: so is `need` but over a NaN height; the
      // divisions by the radii round by a relative 2^-24, a height's rounding, well within the
      // clearance's relative part)
      const float need = isnan(ez) ? INFINITY : value[w] + clearance - ez;
      up_max[w] = fmax(up_max[w], b == 0 ? (need < 0.0f ? -INFINITY : INFINITY) : need / region_band_edge(b));
      down_max[w] = fmax(down_max[w], need / region_band_edge(b + 1));
      rec[4 + 2 * w * REGION_END_BANDS + b] = up_max[w];
      rec[4 + (2 * w + 1) * REGION_END_BANDS + b] = down_max[w];
    }
  }
  // (the bands past the last filled: never looked up)
  for (int w = 0; w < REGION_END_WEDGES; ++w)
    for (int b = bands; b < REGION_END_BANDS; ++b)
      rec[4 + 2 * w * REGION_END_BANDS + b] = rec[4 + (2 * w + 1) * REGION_END_BANDS + b] = -INFINITY;
}

// How far from the end E (height ze) the sight line of `length` pixels to the other end (height
// zp) is certified clear by E's record `wedge` (its rising maxima, then its falling ones): the
// bands from E whose running maximum of required slopes lies below the line's slope (a count, found
// by bisection: the maxima only grow outward). Then every cell along that stretch would be leapt by
// the march (each point of the stretch lies in a band whose value holds the cell's highest corner,
// below the segment there by the march's clearance), so the march, which finds the same hits with
// or without leaps, finds none there. 0 when the first band fails (an end on the surface always: its own
// corner). The slope's rounding and the required slopes' lie within the clearance's second half.
inline float region_end_reach(HFVIS_GLOBAL const float* wedge, int bands, float length, float ze, float zp) {
  const float slope = (zp - ze) / length;
  HFVIS_GLOBAL const float* maxima = slope >= 0.0f ? wedge : wedge + REGION_END_BANDS;
  // The first band whose maximum does not lie below the slope (`bands` if none).
  int count = 0, past = bands;
  while (count < past) {
    const int mid = (count + past) >> 1;
    if (maxima[mid] < slope)
      count = mid + 1;
    else
      past = mid;
  }
  return count == 0 ? 0.0f : fmin(region_band_edge(count), length);
}

// Whether the surface over cell `cell` (the index of its first corner) rises above the segment
// from (xa, ya, za) to (xb, yb, zb) by so much that the march (region_sight_visible) must find it
// hidden: at the middle of the segment's stretch over the cell, by more than the march's
// rounding (`margin`, the field's part, and the segment's own), more than the rounding it forgives
// (region_forgiven, and region_position_reach times `gradient`) and more than its values can change
// over the 1e-3 pixel of a piece whose inside it skips
// (`gradient`: a bound of the surface's slope per pixel). Only over a cell whose 4 x 4 heights around are
// finite, so that every value the march takes near there is a number (not looked at where `finite_field` says
// every height of the field is). The cheap test of a sight line against the
// cell that hid the previous one (sight lines to neighbouring samples are often hidden by the
// same cell); 0 decides nothing.
HFVIS_SIGHT_INLINE int region_cull_hides(HFVIS_GLOBAL const float* h, int width, int height, float cell_x,
                                         float cell_y, float curvature, float max_d2, float margin,
                                         float gradient, int finite_field, int cell, float xa, float ya,
                                         float za, float xb, float yb, float zb) {
  const int cx = cell % width, cy = cell / width;
  const float dx = xb - xa, dy = yb - ya, dz = zb - za;
  const float pixels = fabs(dx) > fabs(dy) ? fabs(dx) : fabs(dy);
  if (pixels == 0.0f) return 0;
  float lo = 0.0f, hi = 1.0f;
  if (dx != 0.0f) {
    const float t1 = ((float)cx - xa) / dx, t2 = ((float)(cx + 1) - xa) / dx;
    lo = fmax(lo, fmin(t1, t2)), hi = fmin(hi, fmax(t1, t2));
  } else if (xa < (float)cx || xa > (float)(cx + 1)) {
    return 0;
  }
  if (dy != 0.0f) {
    const float t1 = ((float)cy - ya) / dy, t2 = ((float)(cy + 1) - ya) / dy;
    lo = fmax(lo, fmin(t1, t2)), hi = fmin(hi, fmax(t1, t2));
  } else if (ya < (float)cy || ya > (float)(cy + 1)) {
    return 0;
  }
  if (!(hi > lo)) return 0;
  for (int y = (cy > 0 ? cy - 1 : 0); !finite_field && y <= (cy + 2 < height ? cy + 2 : height - 1); ++y)
    for (int x = (cx > 0 ? cx - 1 : 0); x <= (cx + 2 < width ? cx + 2 : width - 1); ++x)
      if (!isfinite(h[y * width + x])) return 0;
  const float gx = dx * cell_x, gy = dy * cell_y, d2 = gx * gx + gy * gy;
  if (max_d2 > 0.0f && d2 > max_d2) return 1;  // out of reach: the march says hidden too
  const float cdd = curvature * d2, tm = 0.5f * (lo + hi);
  float u = xa + tm * dx - (float)cx, v = ya + tm * dy - (float)cy;
  u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
  v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
  const int p = cy * width + cx;
  const float h00 = h[p], h10 = h[p + 1], h01 = h[p + width], h11 = h[p + width + 1];
  const float s = h00 + (h10 - h00) * u + (h01 - h00) * v + (h00 - h10 - h01 + h11) * u * v;
  const float f = region_rise(s, tm, za, dz, cdd);
  const float slack = margin + 1e-5f * (2.0f * (fabs(za) + fabs(zb)) + fabs(cdd)) +
                      1.5e-3f * (1.5f * gradient + (fabs(dz) + fabs(cdd)) / pixels) +
                      region_forgiven(za, zb, cdd) + region_position_reach(xa, ya, xb, yb) * gradient;
  return f > slack;
}

// A 32-bit integer hash (Wellons' lowbias32): the jitter of the samples.
inline unsigned int region_hash(unsigned int x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// A region table's seed: the run's `seed` mixed with the table's rectangle's corners (whole
// pixels; a points table's bounds, inside the field, whose samples take no jitter), so that two
// rectangles of one size drawn with one seed get unrelated jitters (else a pair's samples k and k
// sat at the same place in their strata) and a rectangle draws the same samples as receivers or
// as sources. What region_sample takes; computed once per table, not per sample.
inline unsigned int region_table_seed(HFVIS_GLOBAL const float* table, unsigned int seed) {
  const unsigned int lo = (unsigned int)(int)table[0] + 0x9e3779b9U * (unsigned int)(int)table[1];
  const unsigned int hi = (unsigned int)(int)table[2] + 0x9e3779b9U * (unsigned int)(int)table[3];
  return seed ^ region_hash(lo ^ region_hash(hi));
}

// The jitter in [0, 1) of coordinate `axis` (0 or 1) of sample s of the stream `key` (0 for a
// region's own samples, receiver + 1 for the sources decorrelated per receiver): 24 bits, exact
// in float. `seed`: the table's (region_table_seed).
inline float region_jitter(unsigned int seed, unsigned int key, unsigned int s, unsigned int axis) {
  const unsigned int v = region_hash(seed ^ region_hash(key ^ region_hash(2U * s + axis)));
  return (float)(v >> 8) * 0x1p-24f;
}

// Sample s of a region's table, drawn from stream `key` of `seed` (the table's: region_table_seed):
// the table holds the rectangle (lo_x, lo_y, hi_x, hi_y), then per sample its stratum's corner
// (x, y), its size (x, y) and the height (above the surface, or absolute when `absolute`). The
// sample is the corner plus the jitter times the size, kept inside the rectangle (a rounding may
// step past).
// *z: its absolute height (NaN over a nodata surface).
inline void region_sample(HFVIS_GLOBAL const float* table, HFVIS_GLOBAL const float* h, int width, int height,
                          int absolute, unsigned int seed, unsigned int key, int s, float* x, float* y,
                          float* z) {
  HFVIS_GLOBAL const float* e = table + 4 + 5 * s;
  const float vx = e[0] + region_jitter(seed, key, (unsigned int)s, 0U) * e[2];
  const float vy = e[1] + region_jitter(seed, key, (unsigned int)s, 1U) * e[3];
  *x = vx < table[0] ? table[0] : (vx > table[2] ? table[2] : vx);
  *y = vy < table[1] ? table[1] : (vy > table[3] ? table[3] : vy);
  *z = absolute ? e[4] : region_surface_at(h, width, height, *x, *y) + e[4];
}

#endif  // HFVIS_REGION_SIGHT_CL
