// viewshed.cl: what one observer sees on the bilinear surface (computeViewshed in
// src/ops/viewshed.cpp; the method is described in hfvis/viewshed.hpp).
//
// Coordinates are pixels (column x, row y); heights are z-scaled and NaN at nodata. A sight
// line runs from the eye E (a grid point, height ze) to the target T (a grid point, height
// zt): point t in [0, 1] lies over E + t (T - E), at ground distance t D, its sight line at
// ze + t (zt - ze). The surface there, lowered for the Earth's curvature, is
// s(t) = h(E + t (T - E)) - c (t D)^2. Within one cell the bilinear surface along the line is
// a quadratic in t, so the test "does s rise strictly above the sight line" is decided per cell
// from the two ends and the vertex. A cell with a nodata corner has no surface.
//
// The kernels, in the order they run: viewshed_slopes and viewshed_lipschitz (a bound on the
// surface's slope around each cell) and the maximum pyramid, once per field; per observer,
// viewshed_cull (the culling pyramid's query, with one), viewshed_classify (one work-item per
// target: what the range, nodata and the culling settle), viewshed_ray_need (with culling: how
// far the rays must go), viewshed_rays (one work-item per ray from E to a point of the box's
// border: bounds on the largest elevation slope met, with which it settles the targets of its
// wedge as it passes them), the pending targets' list, and viewshed_march (one work-item per
// pending target: an exact march, cut short by its ray's upper bound where that settles it).
#pragma OPENCL FP_CONTRACT OFF

#include "shared/fast_math.cl"
#include "shared/lanes.cl"

// Divisions and square roots in the bounds and the classification are native_ ones: the program
// is built for correctly rounded ones (which the exact marches' few divisions keep), whose
// library calls cost more than the rest of a target there. Their last bits only move bounds
// by rounding, as float arithmetic does anyway.

// Integer clamp as compare and select (PoCL makes library calls of the builtin in scalar code).
inline int clamp_int(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

typedef struct {
  int width, height;     // the field
  float cell_x, cell_y;  // ground units per pixel
  float curvature;       // c: a point at ground distance d lies c d^2 lower
} Field;

inline float sample_cell(__global const float* h, int width, int cx, int cy, int x1, int y1, float u, float v) {
  const float h00 = h[cy * width + cx], h10 = h[cy * width + x1];
  const float h01 = h[y1 * width + cx], h11 = h[y1 * width + x1];
  const float top = h00 + (h10 - h00) * u, bottom = h01 + (h11 - h01) * u;
  return top + (bottom - top) * v;
}

// The cell under the point (x, y) of a segment's middle, clamped to the field; its corners'
// far column and row (equal to the cell's own on a field one pixel wide or high).
inline int4 cell_of(float x, float y, int width, int height) {
  const int cx = clamp_int((int)floor(x), 0, width > 2 ? width - 2 : 0);
  const int cy = clamp_int((int)floor(y), 0, height > 2 ? height - 2 : 0);
  return (int4)(cx, cy, cx + 1 < width ? cx + 1 : cx, cy + 1 < height ? cy + 1 : cy);
}

// The twist of a cell (h00 - h10 - h01 + h11): the t^2 coefficient of the surface along a
// line is twist * dx * dy.
inline float cell_twist(__global const float* h, int width, int4 c) {
  return h[c.y * width + c.x] - h[c.y * width + c.z] - h[c.w * width + c.x] + h[c.w * width + c.z];
}

// The t^2 coefficient of the surface along a line of steps (dx, dy) in cell c: twist * dx * dy, and
// 0 along a grid line (dx dy = 0), where the surface is an edge's straight line even beside a
// cell with a nodata corner.
inline float surface_curve(__global const float* h, int width, int4 c, float dx, float dy) {
  return dx * dy != 0.0f ? cell_twist(h, width, c) * dx * dy : 0.0f;
}

// The largest value on [0, 1] of the quadratic with ends f0, f1 and t^2 coefficient a (in the
// segment's own parameter), or -INFINITY where it stays at or below its ends' larger one:
// f(s) = f0 + (f1 - f0) s + bump s (1 - s), bump = -a. Branch-free, for scalars and lanes.
#define HFVIS_QUADRATIC_BUMP(F)                                                                                  \
  HFVIS_INLINE HFVIS_OVERLOADABLE F quadratic_bump(F f0, F f1, F a) {                                             \
    const F bump = -a;                                                                                           \
    const F s = 0.5f + native_divide(f1 - f0, 2.0f * bump);                                                      \
    return ((a < 0.0f) & (s > 0.0f) & (s < 1.0f)) ? f0 + (f1 - f0) * s + bump * s * (1.0f - s) : (F)(-INFINITY); \
  }
HFVIS_QUADRATIC_BUMP(float)
#if HFVIS_LANES > 1
HFVIS_QUADRATIC_BUMP(lane_float)
#endif

// The parameter t where a line from e (along d, 1 / d = inv) crosses grid line g, or INFINITY when
// g is not strictly before the line's end e + d (or the line runs along the axis, d = 0): a
// crossing at the end itself would be a rounded copy of t = 1.
inline float crossing(float g, float e, float d, float inv) {
  return d != 0.0f && (d > 0.0f ? g < e + d : g > e + d) ? (g - e) * inv : INFINITY;
}

// The grid lines of one axis that a line from grid point e to e + d crosses, walked in order:
// the next one, g (column lines for the x axis, row lines for y), its parameter t (INFINITY
// once none is left before the line's end), and where the line crosses it across the axis,
// e_across + q + r / den with 0 <= r < den = |d_along|, kept in integers (a crossing at a grid
// point is one exactly, and no division is made per crossing): from one grid line to the next
// the crossing moves by d_across / den = dq + dr / den.
typedef struct {
  float g, t, inv_den;
  int q, r, den, dq, dr;
} Axis;

inline Axis axis_start(float g, float e_along, float d_along, float inv_along, float d_across) {
  Axis a;
  a.g = g;
  a.t = crossing(g, e_along, d_along, inv_along);
  a.den = max((int)fabs(d_along), 1);
  a.inv_den = 1.0f / a.den;
  const long n = (long)((int)g - (int)e_along) * (long)d_across * (d_along < 0.0f ? -1 : 1);
  long q = n / a.den, r = n % a.den;
  if (r < 0) q -= 1, r += a.den;
  a.q = (int)q;
  a.r = (int)r;
  a.dq = (int)d_across / a.den;
  a.dr = (int)d_across % a.den;
  if (a.dr < 0) a.dq -= 1, a.dr += a.den;
  return a;
}

inline void axis_next(Axis* a, float e_along, float d_along, float inv_along) {
  a->g += sign(d_along);
  a->t = crossing(a->g, e_along, d_along, inv_along);
  a->q += a->dq;
  a->r += a->dr;
  if (a->r >= a->den) a->r -= a->den, a->q += 1;
}

// The surface where the line crosses the x axis's next column line (x_axis) or the y axis's next
// row line: the linear interpolation between the grid line's two heights around the crossing.
// A point of an edge whose two heights are valid is surface even where the cells beside it are
// not.
inline float surface_at_crossing(__global const float* h, int width, int x_axis, const Axis* a, int ex, int ey) {
  const size_t at = x_axis ? (size_t)(ey + a->q) * width + (int)a->g : (size_t)a->g * width + (ex + a->q);
  if (a->r == 0) return h[at];
  const float lo = h[at], hi = h[at + (x_axis ? width : 1)];
  return lo + (hi - lo) * ((float)a->r * a->inv_den);
}

// The largest value of f(t) / t on a piece [t0, t1] of the line where f, the surface less the
// sight line, is the quadratic with ends f0, f1 and t^2 coefficient a_t (in t): at its ends and
// where (f / t)' = 0, t^2 = t0 t1 + f_lin(0) / a_t (a maximum only where a_t < 0). On the first
// piece (t0 = 0) f0 is the eye's height below the surface: f / t runs to -inf (f0 < 0), to
// f'(0) (f0 = 0) or to +inf.
inline float excess_on_piece(float t0, float t1, float f0, float f1, float a_t) {
  float best = f1 / t1;
  if (t0 > 0.0f)
    best = hf_max(best, f0 / t0);
  else if (f0 > 0.0f)
    return INFINITY;
  else if (f0 == 0.0f)
    best = hf_max(best, (f1 - f0) / t1 - a_t * t1);
  if (a_t < 0.0f) {
    const float span = t1 - t0;
    const float tt = t0 * t1 + (f0 * t1 - f1 * t0) / span / a_t;
    const float tv = tt > 0.0f ? sqrt(tt) : 0.0f;
    if (tv > t0 && tv < t1) {
      const float u = (tv - t0) / span;
      best = hf_max(best, (f0 + (f1 - f0) * u - a_t * span * span * u * (1.0f - u)) / tv);
    }
  }
  return best;
}

// How far the surface may rise above a sight line from the eye at height ze (rise: the target's
// height, lowered by drop, less ze; drop: the curvature's c D^2) and still not hide the target:
// the heights' rounding, which a grazing sight line forgives, as region visibility's march
// (region_forgiven) and viewcount's tie rule do (docs/ALGORITHMS.md, "Grazing samples and the
// heights' rounding"). On a tilted plane a sight line between two points of the surface runs
// along it, and an exact sign hid nearly every such target (all of them on a plane at 8848).
// 2^-21 of |ze| + |the target's height| + |drop| (region_forgiven's of the same segment): about 8
// units in the last place of the larger height.
inline float forgiven_rise(float ze, float rise, float drop) {
  return 0x1p-21f * (fabs(ze) + fabs(ze + rise + drop) + fabs(drop));
}

// What a sight line forgives over cell c: forgiven_rise's, or where more, 2^-21 of the cell's
// largest |corner|. The surface there is interpolated from the corners and rounds by units in the
// last place of them, which the ends' heights do not bound where a plane crosses 0 between the
// eye and the target: on an exact plane 0.375 x + 1.25 y seen from its 0 at height 0, 7 of 369
// targets were hidden (a probe's find). At most 2^-21 of the field's largest |height|, which the
// rays' bound forgives already (ViewshedRun::forgivenRise).
inline float cell_forgiven(__global const float* h, int width, int4 c, float forgiven) {
  const float corners = fmax(fmax(fabs(h[c.y * width + c.x]), fabs(h[c.y * width + c.z])),
                             fmax(fabs(h[c.w * width + c.x]), fabs(h[c.w * width + c.z])));
  return fmax(forgiven, 0x1p-21f * corners);
}

// March of the sight line from E (ex, ey) along (dx, dy) over t in [ta, tb] (0 <= ta < tb <= 1),
// cell by cell. rise: zt - ze; d2: D^2; target_height: the sight line's height above the surface
// at t = 1, taken as it is rather than as the rounded difference of the two. Returns 1 where the
// surface rises above the sight line by more than the rounding it forgives (forgiven_rise, or
// cell_forgiven's over a cell) somewhere on [ta, tb]: at a grid-line crossing, or inside a cell without
// nodata at the top of its quadratic. With `excess` (not null) it marches all of [ta, tb] and raises *excess
// to the largest f(t) / t met (f the surface less the sight line, nothing forgiven: a rounding forgiven near
// the eye would lower a far target's need by it times their distances' ratio): a target needs max(0,
// target_height + that) above the surface to be seen exactly.
int sight_walk(__global const float* h, Field f, float ex, float ey, float dx, float dy, float ze, float rise,
               float d2, float target_height, float ta, float tb, float* excess) {
  const float inv_dx = dx != 0.0f ? 1.0f / dx : 0.0f, inv_dy = dy != 0.0f ? 1.0f / dy : 0.0f;
  // The next grid lines crossed after ta.
  Axis ax = axis_start(dx > 0.0f ? floor(ex + ta * dx) + 1.0f : ceil(ex + ta * dx) - 1.0f, ex, dx, inv_dx, dy);
  Axis ay = axis_start(dy > 0.0f ? floor(ey + ta * dy) + 1.0f : ceil(ey + ta * dy) - 1.0f, ey, dy, inv_dy, dx);
  const float drop = f.curvature * d2;
  const float forgiven = forgiven_rise(ze, rise, drop);
  const float pixels = hf_max(fabs(dx), fabs(dy));
  float t0 = ta, f0 = NAN;
  if (ta == 0.0f) f0 = h[(int)ey * f.width + (int)ex] - ze;
  while (t0 < tb) {
    const float tx = ax.t, ty = ay.t;
    const float t1 = hf_min(hf_min(tx, ty), tb);
    const float tm = 0.5f * (t0 + t1);
    const int4 c = cell_of(ex + tm * dx, ey + tm * dy, f.width, f.height);
    // At a grid-line crossing (a march may also end on one) the grid line's surface; at an end
    // inside a cell the cell's.
    const float s1 =
        t1 == tx   ? surface_at_crossing(h, f.width, 1, &ax, (int)ex, (int)ey)
        : t1 == ty ? surface_at_crossing(h, f.width, 0, &ay, (int)ex, (int)ey)
                   : sample_cell(h, f.width, c.x, c.y, c.z, c.w, (ex - c.x) + t1 * dx, (ey - c.y) + t1 * dy);
    const float f1 = t1 == 1.0f ? (isnan(s1) ? NAN : -target_height) : (s1 - ze) - t1 * rise - drop * t1 * t1;
    if (isnan(f0)) {  // the start of a march past the eye
      // (the fraction from the eye's grid point, a whole number of pixels from the cell's corner: the
      // absolute position ex + t0 dx would round by units in the last place of the column, which
      // times the surface's slope passed the rounding forgiven where a plane crosses 0 far from the
      // field's corner, and hid 6970 of 65536 targets on h = column - 200 seen from column 200)
      const float s0 =
          sample_cell(h, f.width, c.x, c.y, c.z, c.w, (ex - c.x) + t0 * dx, (ey - c.y) + t0 * dy);
      f0 = (s0 - ze) - t0 * rise - drop * t0 * t0;
    }
    const float span = t1 - t0;
    const float a = (surface_curve(h, f.width, c, dx, dy) - drop) * span * span;
    // A piece shorter than 1e-3 pixel (a march begun a rounding away from a crossing or the
    // target) rises at most |twist| 2.5e-7 above its ends: its vertex would be rounding noise.
    const float bump = span * pixels > 1e-3f ? quadratic_bump(f0, f1, a) : -INFINITY;
    if (excess) {
      if (!isnan(f1)) *excess = hf_max(*excess, f1 / t1);
      if (!isnan(f0) && !isnan(f1) && span > 0.0f)
        *excess = hf_max(*excess,
                         excess_on_piece(t0, t1, f0, f1, span * pixels > 1e-3f ? a / (span * span) : 0.0f));
    } else if (f0 > forgiven || f1 > forgiven || bump > forgiven) {
      const float tolerance = cell_forgiven(h, f.width, c, forgiven);  // (read only here: seldom)
      if (f0 > tolerance || f1 > tolerance || bump > tolerance) return 1;
    }
    f0 = f1;
    if (tx <= t1) axis_next(&ax, ex, dx, inv_dx);
    if (ty <= t1) axis_next(&ay, ey, dy, inv_dy);
    t0 = t1;
  }
  return 0;
}

inline int sight_blocked(__global const float* h, Field f, float ex, float ey, float dx, float dy, float ze, float rise,
                         float d2, float target_height, float ta, float tb) {
  return sight_walk(h, f, ex, ey, dx, dy, ze, rise, d2, target_height, ta, tb, 0);
}

// The maximum pyramid: level k >= 1 holds, per block of 2^k x 2^k cells, the largest height
// of its grid points (the bilinear surface over the block lies below it; nodata left out, NaN
// where the block has no valid point). Level k is levels[k].x blocks wide and levels[k].y high,
// from levels[k].z in `pyramid`. viewshed_pyramid_first builds level 1 from the heights,
// viewshed_pyramid_next level k from level k - 1.
__kernel void viewshed_pyramid_first(__global const float* h, Field f, int4 level, __global float* pyramid) {
  const int bx = get_global_id(0), by = get_global_id(1);
  if (bx >= level.x || by >= level.y) return;
  float m = NAN;
  for (int y = 2 * by; y <= min(2 * by + 2, f.height - 1); ++y)
    for (int x = 2 * bx; x <= min(2 * bx + 2, f.width - 1); ++x) m = fmax(m, h[y * f.width + x]);
  pyramid[level.z + by * level.x + bx] = m;
}

__kernel void viewshed_pyramid_next(int4 below, int4 level, __global float* pyramid) {
  const int bx = get_global_id(0), by = get_global_id(1);
  if (bx >= level.x || by >= level.y) return;
  float m = NAN;
  for (int y = 2 * by; y <= min(2 * by + 1, below.y - 1); ++y)
    for (int x = 2 * bx; x <= min(2 * bx + 1, below.x - 1); ++x) m = fmax(m, pyramid[below.z + y * below.x + x]);
  pyramid[level.z + by * level.x + bx] = m;
}

// The block of side `size` (a power of two, in cells) holding the line's point at coordinate p
// going in direction d, and the coordinate where the line leaves it (INFINITY along d = 0).
inline int block_of(float p, float d, int size, int blocks) {
  const float b = d < 0.0f ? ceil(p / size) - 1.0f : floor(p / size);
  return clamp_int((int)b, 0, blocks - 1);
}

// sight_blocked over [ta, tb], skipping every block of the pyramid that lies wholly below the
// sight line: a block's largest height, lowered by the curvature drop at the block's nearest
// point, at or below the sight line's lower end over the block. Where no block can be skipped,
// the cells of one level-1 block are marched exactly.
// With `excess`, as sight_walk's: a block is skipped where f / t cannot exceed *excess in it.
int sight_blocked_pyramid(__global const float* h, __global const float* pyramid, __constant int4* levels,
                          int top_level, Field f, float ex, float ey, float dx, float dy, float ze, float rise,
                          float d2, float target_height, float ta, float tb, float* excess) {
  const float inv_dx = dx != 0.0f ? 1.0f / dx : 0.0f, inv_dy = dy != 0.0f ? 1.0f / dy : 0.0f;
  const float drop = f.curvature * d2;
  const float pixel_t = 1.0f / fmax(fabs(dx), fabs(dy));
  float t = ta;
  int k = 1;
  while (t < tb) {
    const float x = ex + t * dx, y = ey + t * dy;
    const float line_t = ze + t * rise;
    for (;;) {
      const int4 L = levels[k];
      const int size = 1 << k;
      const int bx = block_of(x, dx, size, L.x), by = block_of(y, dy, size, L.y);
      const float exit_x = crossing(dx < 0.0f ? bx * size : (bx + 1) * size, ex, dx, inv_dx);
      const float exit_y = crossing(dy < 0.0f ? by * size : (by + 1) * size, ey, dy, inv_dy);
      float t_exit = hf_min(hf_min(exit_x, exit_y), tb);
      const float low = hf_min(line_t, ze + t_exit * rise);
      // The least the block is lowered: at its nearest point, or its farthest where the "drop"
      // raises (negative curvature).
      const float fall = drop >= 0.0f ? drop * t * t : drop * t_exit * t_exit;
      const float top = pyramid[L.z + by * L.x + bx] - fall - low;  // f's bound over the block
      const int below = excess ? (top >= 0.0f ? (t > 0.0f && top / t <= *excess) : top / t_exit <= *excess)
                               : top <= 0.0f;
      if (t_exit > t && below) {  // the block lies below the sight line (or adds no excess)
        t = t_exit;
        k = k < top_level ? k + 1 : top_level;
        break;
      }
      if (k == 1) {  // march the block's cells (a pixel's length where rounding put t at its exit)
        // Within half a pixel of tb, tb itself: t + pixel_t may round short of it (0.99999994 for
        // the target, whose own point would then be marched as surface).
        if (!(t_exit > t)) t_exit = t + pixel_t < tb - 0.5f * pixel_t ? t + pixel_t : tb;
        if (sight_walk(h, f, ex, ey, dx, dy, ze, rise, d2, target_height, t, t_exit, excess)) return 1;
        t = t_exit;
        break;
      }
      --k;
    }
  }
  return 0;
}

// slopes[cell]: a bound on the surface's ground slope |grad h| anywhere in the cell (the
// derivative along x lies between its two x edges' differences, and so for y), INFINITY where a
// corner is nodata. Cells are indexed by their corner (x, y), x < max(width - 1, 1),
// y < max(height - 1, 1).
__kernel void viewshed_slopes(__global const float* h, Field f, __global float* slopes) {
  const int x = get_global_id(0), y = get_global_id(1);
  const int cells_x = f.width > 1 ? f.width - 1 : 1, cells_y = f.height > 1 ? f.height - 1 : 1;
  if (x >= cells_x || y >= cells_y) return;
  const int x1 = x + 1 < f.width ? x + 1 : x, y1 = y + 1 < f.height ? y + 1 : y;
  const float h00 = h[y * f.width + x], h10 = h[y * f.width + x1];
  const float h01 = h[y1 * f.width + x], h11 = h[y1 * f.width + x1];
  const float gx = hf_max(fabs(h10 - h00), fabs(h11 - h01)) / f.cell_x;
  const float gy = hf_max(fabs(h01 - h00), fabs(h11 - h10)) / f.cell_y;
  const float g = sqrt(gx * gx + gy * gy) * 1.0001f;  // rounding of the bound itself
  slopes[y * cells_x + x] = isfinite(h00) && isfinite(h10) && isfinite(h01) && isfinite(h11) ? g : INFINITY;
}

// lipschitz[cell]: the largest of slopes over the 3 x 3 cells around the cell (cells past the
// field left out): a bound on the surface's slope within a pixel of any point of the cell.
__kernel void viewshed_lipschitz(__global const float* slopes, Field f, __global float* lipschitz) {
  const int x = get_global_id(0), y = get_global_id(1);
  const int cells_x = f.width > 1 ? f.width - 1 : 1, cells_y = f.height > 1 ? f.height - 1 : 1;
  if (x >= cells_x || y >= cells_y) return;
  float bound = 0.0f;
  for (int j = y > 0 ? y - 1 : 0; j <= (y + 1 < cells_y ? y + 1 : y); ++j)
    for (int i = x > 0 ? x - 1 : 0; i <= (x + 1 < cells_x ? x + 1 : x); ++i) bound = hf_max(bound, slopes[j * cells_x + i]);
  lipschitz[y * cells_x + x] = bound;
}

// The border point p of the box [x0, x1] x [y0, y1] (w = x1 - x0 + 1, hh = y1 - y0 + 1 points
// a side): clockwise from (x0, y0) along the top row, down the right column, back along the
// bottom row and up the left column. 2 (w - 1) + 2 (hh - 1) points.
inline float2 border_point(int p, int4 box) {
  const int w1 = box.z - box.x, h1 = box.w - box.y;
  if (p <= w1) return (float2)(box.x + p, box.y);
  p -= w1;
  if (p <= h1) return (float2)(box.z, box.y + p);
  p -= h1;
  if (p <= w1) return (float2)(box.z - p, box.w);
  p -= w1;
  return (float2)(box.x, box.w - p);
}

// The position along the border (as border_point counts, a real number) where the ray from E
// through T leaves the box.
inline float border_position(float ex, float ey, float dx, float dy, int4 box) {
  const int w1 = box.z - box.x, h1 = box.w - box.y;
  const float lx = dx > 0.0f ? native_divide(box.z - ex, dx) : dx < 0.0f ? native_divide(box.x - ex, dx) : INFINITY;
  const float ly = dy > 0.0f ? native_divide(box.w - ey, dy) : dy < 0.0f ? native_divide(box.y - ey, dy) : INFINITY;
  if (lx <= ly) {
    const float y = hf_min(hf_max(ey + lx * dy, (float)box.y), (float)box.w);
    return dx > 0.0f ? w1 + (y - box.y) : 2 * w1 + h1 + (box.w - y);
  }
  const float x = hf_min(hf_max(ex + ly * dx, (float)box.x), (float)box.z);
  return dy < 0.0f ? x - box.x : w1 + h1 + (box.z - x);
}

// The ground angle between the rays from E to border points a and b.
inline float ray_angle(float ex, float ey, int a, int b, int4 box, Field f) {
  const float2 pa = border_point(a, box), pb = border_point(b, box);
  const float ax = (pa.x - ex) * f.cell_x, ay = (pa.y - ey) * f.cell_y;
  const float bx = (pb.x - ex) * f.cell_x, by = (pb.y - ey) * f.cell_y;
  if ((ax == 0.0f && ay == 0.0f) || (bx == 0.0f && by == 0.0f)) return M_PI_F;
  return atan2(fabs(ax * by - ay * bx), ax * bx + ay * by);
}

inline void put_visible(__global float* out, size_t p, float v, int accumulate) {
  if (accumulate)
    out[p] += v;
  else
    out[p] = v;
}

// A target's sight line, from the eye (ex_i, ey_i, height ze) to grid point (x, y): its steps in
// pixels, squared ground length and length, its rise (the target's height, lowered for the
// curvature, less the eye's) and elevation slope. viewshed_rays and viewshed_march compute it
// alike, so that the part of the line a ray's bounds cover is the part the march leaves out.
typedef struct {
  float dx, dy, d2, dist, rise, slope;
} SightLine;

inline SightLine sight_line(__global const float* h, Field f, int x, int y, int ex_i, int ey_i, float ze,
                            float target_height) {
  SightLine s;
  s.dx = x - ex_i;
  s.dy = y - ey_i;
  const float gdx = s.dx * f.cell_x, gdy = s.dy * f.cell_y;
  s.d2 = gdx * gdx + gdy * gdy;
  s.dist = native_sqrt(s.d2);
  s.rise = (h[(size_t)y * f.width + x] + target_height - f.curvature * s.d2) - ze;
  s.slope = native_divide(s.rise, s.dist);
  return s;
}

// How far short of the target viewshed_march's exact part of a sight line begins: 2.5 pixels,
// where the bounds of a ray two grid lines short of the target reach along an axis (one along a
// diagonal). A line no longer is marched whole.
inline float split_length(Field f) { return 2.5f * hf_max(f.cell_x, f.cell_y); }

// Memory access for settle_targets, for scalars and lanes (a lane not `go` reads the first entry,
// and writes nothing).
HFVIS_INLINE HFVIS_OVERLOADABLE int lanes_any(int m) { return m != 0; }
HFVIS_INLINE HFVIS_OVERLOADABLE int load_pending(__global const uchar* pending, int p, int go) {
  return go ? pending[p] : 0;
}
HFVIS_INLINE HFVIS_OVERLOADABLE float load_height(__global const float* h, int p, int go) { return h[go ? p : 0]; }
HFVIS_INLINE HFVIS_OVERLOADABLE void store_settled(__global uchar* pending, __global float* ray_hi,
                                                   __global float* out_visible, int accumulate, int p, int hidden,
                                                   int keep, float bound) {
  if (hidden) {
    put_visible(out_visible, p, 0.0f, accumulate);
    pending[p] = 0;
  } else if (keep) {
    ray_hi[p] = bound;
  }
}
#if HFVIS_LANES > 1
HFVIS_INLINE lane_float gather(__global const float* p, lane_int at) {
  lane_float v;
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) LANE(v, l) = p[ILANE(at, l)];
  return v;
}

HFVIS_INLINE HFVIS_OVERLOADABLE int lanes_any(lane_int m) { return any_lane(m); }
HFVIS_INLINE HFVIS_OVERLOADABLE lane_int load_pending(__global const uchar* pending, lane_int p, lane_int go) {
  lane_int v;
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) ILANE(v, l) = ILANE(go, l) ? pending[ILANE(p, l)] : 0;
  return v;
}
HFVIS_INLINE HFVIS_OVERLOADABLE lane_float load_height(__global const float* h, lane_int p, lane_int go) {
  return gather(h, go ? p : (lane_int)0);
}
HFVIS_INLINE HFVIS_OVERLOADABLE void store_settled(__global uchar* pending, __global float* ray_hi,
                                                   __global float* out_visible, int accumulate, lane_int p,
                                                   lane_int hidden, lane_int keep, lane_float bound) {
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l)
    store_settled(pending, ray_hi, out_visible, accumulate, ILANE(p, l), ILANE(hidden, l), ILANE(keep, l),
                  LANE(bound, l));
}
#endif

// The targets of ray r's wedge (a, b: its border point and the next one, less the eye) on grid
// line m of the ray's major axis (a column where the ray runs at most 45 degrees from the x
// axis, else a row), where `live`; for every sight line of the wedge the ray holds, over its
// prefix so far (d_ray from the eye), bounds lo <= the largest slope met <= an upper bound,
// and that bound over a shorter prefix (d_back): hi_ray / hi_ray_back along the ray itself,
// hi / hi_back for a sight line at the wedge's far side (see ray_bounds). A target still
// pending (left open by viewshed_classify) is hidden where its slope lies below lo and the
// prefix ends short of it; else the bound over the shorter prefix that reaches its split
// distance, at the target's angle from the ray, is kept for viewshed_march, which marches the
// rest exactly. Targets neither settles keep ray_hi = INFINITY (a whole march). Ray r crosses
// line m at e_minor + qa + ra / den (exactly; side a of the wedge; inv_den = 1 / den), side b
// (b_along: where it runs the same way along the axis) at e_minor + (m - e_major) * slope_b;
// the wedge meets the line in at most about a pixel. For scalars and lanes alike (L the long
// type, CL / CI / CF conversions to it, to int and to float).
#define HF_MIN(a, b) ((a) < (b) ? (a) : (b))
#define HFVIS_SETTLE(F, I, L, CL, CI, CF)                                                                           \
  HFVIS_INLINE HFVIS_OVERLOADABLE void settle_targets(                                                              \
      __global const float* h, Field f, int ex_i, int ey_i, float ze, float target_height, int4 box, int x_major,   \
      I live, I m, I qa, I ra, F inv_den, I b_along, F slope_b, I a_x, I a_y, I b_x, I b_y, F b_length, F lo,       \
      F hi_ray, F hi, F d_ray, F hi_ray_back, F hi_back, F d_back, __global uchar* pending, __global float* ray_hi, \
      __global float* out_visible, int accumulate) {                                                                \
    const int e_major = x_major ? ex_i : ey_i, e_minor = x_major ? ey_i : ex_i;                                     \
    live = live & (m >= (x_major ? box.x : box.y)) & (m <= (x_major ? box.z : box.w));                              \
    const F ma = e_minor + CF(qa) + CF(ra) * inv_den;                                                               \
    const F mb = b_along ? e_minor + CF(m - e_major) * slope_b : ma;                                                \
    /* The grid points between the sides: a's is exact, so none on side a is missed (b's side is */               \
    /* not in the wedge). */                                                                                        \
    const int minor_lo = x_major ? box.y : box.x, minor_hi = x_major ? box.w : box.z;                               \
    const I a_below = ma <= mb;                                                                                     \
    const I first = max(a_below ? e_minor + qa + (ra > 0 ? (I)1 : (I)0) : CI(ceil(mb)), minor_lo);                  \
    const I last = min(min(a_below ? CI(floor(mb)) : e_minor + qa, minor_hi), first + 3);                           \
    /* Distances compared in squares, with margins far above their rounding: the prefix ends a */                  \
    /* quarter pixel short of a target (for lo), or reaches its split distance dist - split_length */              \
    /* (for hi): dist <= (d + split_length - margin) (1 - 1e-5), which the march's own root of d2 */                \
    /* keeps within its rounding. */                                                                                \
    const float cell_min = hf_min(f.cell_x, f.cell_y);                                                              \
    const F near = d_ray + 0.25f * cell_min;                                                                        \
    const F reach_back = (d_back + split_length(f) - 1e-3f * cell_min) * (1.0f - 1e-5f);                            \
    const F reach_now = (d_ray + split_length(f) - 1e-3f * cell_min) * (1.0f - 1e-5f);                              \
    const F cross_b = CF(CL(a_x) * CL(b_y) - CL(a_y) * CL(b_x));                                                    \
    for (int j = 0; j < 4; ++j) {                                                                                   \
      const I n = first + j;                                                                                        \
      I go = live & (n <= last);                                                                                    \
      if (!lanes_any(go)) break;                                                                                    \
      const I vx = (x_major ? m : n) - ex_i, vy = (x_major ? n : m) - ey_i;                                         \
      /* In the wedge: a x v >= 0 > b x v. */                                                                       \
      const L cross_a = CL(a_x) * CL(vy) - CL(a_y) * CL(vx);                                                        \
      go = go & CI(cross_a >= 0) & CI(CL(b_x) * CL(vy) - CL(b_y) * CL(vx) < 0);                                     \
      const I p = (vy + ey_i) * f.width + (vx + ex_i);                                                              \
      go = go & (load_pending(pending, p, go) != 0);                                                                \
      if (!lanes_any(go)) continue;                                                                                 \
      /* The target's squared distance and rise as sight_line has them. */                                          \
      const F gx = CF(vx) * f.cell_x, gy = CF(vy) * f.cell_y;                                                       \
      const F d2 = gx * gx + gy * gy, dist = native_sqrt(d2);                                                       \
      const F rise = (load_height(h, p, go) + target_height - f.curvature * d2) - ze;                               \
      /* Something nearer rises above the sight line. */                                                            \
      const I hidden = go & (near * near < d2) & (rise < lo * dist);                                                \
      const I back = d2 <= reach_back * reach_back;                                                                 \
      const I keep = go & !hidden & (back | (d2 <= reach_now * reach_now));                                         \
      /* The bound is convex in the angle from the ray (a maximum of linear functions), so below */                 \
      /* the chord between its two ends: at the angle's share of the wedge's, whose ratio of */                     \
      /* sines (a x v |b| over a x b |v|, ground lengths) bounds it from above. */                                  \
      const F near_side = back ? hi_ray_back : hi_ray, far_side = back ? hi_back : hi;                              \
      const F share = HF_MIN(1.0f, CF(cross_a) * b_length / (cross_b * dist) * (1.0f + 1e-5f));                     \
      const F bound = share == 0.0f                 ? near_side                                                     \
                      : !(far_side < INFINITY) ? (F)INFINITY                                                        \
                                                    : near_side + share * (far_side - near_side);                   \
      store_settled(pending, ray_hi, out_visible, accumulate, p, hidden, keep, bound);                              \
    }                                                                                                               \
  }
HFVIS_SETTLE(float, int, long, (long), (int), (float))
#if HFVIS_LANES > 1
HFVIS_SETTLE(lane_float, lane_int, long8, convert_long8, convert_int8, convert_float8)
#endif

// viewshed_ray_need, one work-item per node of the culling pyramid's finest level (leaf: nodes
// across, down, first node's index, k): where the pyramid culled nodes, the rays need not reach
// them. need[r] (from -1) is raised to how far (in units of `unit`) ray r must go to settle the
// targets of a kept node: the wedges that meet the node lie within the border positions of its
// corners (a rectangle's angular extent from an eye outside it, less than a half turn). A node
// holding the eye needs every ray whole.
__kernel void viewshed_ray_need(__global const uchar* culled, int4 leaf, Field f, int ex_i, int ey_i, int4 box,
                                int rays, float unit, __global int* need) {
  const int nx = get_global_id(0), ny = get_global_id(1);
  if (nx >= leaf.x || ny >= leaf.y) return;
  if (culled[(size_t)leaf.z + (size_t)ny * leaf.x + nx]) return;
  const int side = 1 << leaf.w;
  const int x0 = max(nx * side, box.x), y0 = max(ny * side, box.y);
  const int x1 = min(min(nx * side + side, f.width) - 1, box.z), y1 = min(min(ny * side + side, f.height) - 1, box.w);
  if (x0 > x1 || y0 > y1) return;  // outside the box: out of range
  const float far_x = fmax(fabs((float)(x0 - ex_i)), fabs((float)(x1 - ex_i))) * f.cell_x;
  const float far_y = fmax(fabs((float)(y0 - ey_i)), fabs((float)(y1 - ey_i))) * f.cell_y;
  const int q = (int)(sqrt(far_x * far_x + far_y * far_y) / unit) + 1;
  if (ex_i >= x0 && ex_i <= x1 && ey_i >= y0 && ey_i <= y1) {
    for (int r = 0; r < rays; ++r) atomic_max(&need[r], q);
    return;
  }
  // The node subtends less than a half turn from the eye, and border positions grow with the
  // angle clockwise: its rays run from the most counter-clockwise corner's position to the most
  // clockwise one's (angles measured from the direction to its centre), widened by a ray on each
  // side for the rounding of targets in line with a corner.
  const float cx = 0.5f * (x0 + x1) - ex_i, cy = 0.5f * (y0 + y1) - ey_i;
  float lo_angle = INFINITY, hi_angle = -INFINITY, start = 0.0f, end = 0.0f;
  for (int i = 0; i < 4; ++i) {
    const float vx = (i & 1 ? x1 : x0) - ex_i, vy = (i & 2 ? y1 : y0) - ey_i;
    const float angle = atan2(cx * vy - cy * vx, cx * vx + cy * vy);
    const float pos = border_position(ex_i, ey_i, vx, vy, box);
    if (angle < lo_angle) lo_angle = angle, start = pos;
    if (angle > hi_angle) hi_angle = angle, end = pos;
  }
  float extent = end - start;
  if (extent < 0.0f) extent += rays;
  const int first = (int)floor(start) - 1, last = (int)floor(start + extent) + 2;
  for (int r = first; r <= last; ++r) atomic_max(&need[((r % rays) + rays) % rays], q);
}

// A ray from E to border point r, as viewshed_rays marches it: its wedge (a, b: its border point
// and the next one, less E), its step in pixels and ground length, its wedge's angle and the
// distance where the arc between them reaches a pixel, the curvature drop at its end, its
// grid-line crossings, and how far it must go (the culling's reach). ok: a ray to march (a
// non-empty wedge, an eye inside the box's border, within the reach).
typedef struct {
  int ok, x_major, b_along;
  int2 a, b;
  float2 end;
  float dx, dy, inv_dx, inv_dy, length, angle, arc_limit, drop, reach, slope_b, b_length;
  Axis ax, ay;
} Ray;

HFVIS_INLINE Ray ray_setup(int r, int rays, Field f, int ex_i, int ey_i, int4 box, __global const int* need,
                           int use_need, float unit) {
  Ray y;
  const float ex = ex_i, ey = ey_i;
  y.reach = use_need ? (need[r] + 1) * unit : INFINITY;  // with culling, as far as the kept nodes' targets
  y.end = border_point(r, box);
  const float2 next_end = border_point(r + 1 == rays ? 0 : r + 1, box);
  y.a = (int2)((int)y.end.x - ex_i, (int)y.end.y - ey_i);
  y.b = (int2)((int)next_end.x - ex_i, (int)next_end.y - ey_i);
  y.ok = y.reach > 0.0f && (long)y.a.x * y.b.y - (long)y.a.y * y.b.x > 0;  // else an empty wedge
  // The wedge's angle, widened past the rounding of its few operations.
  y.angle = ray_angle(ex, ey, r, r + 1 == rays ? 0 : r + 1, box, f) * (1.0f + 1e-5f);
  y.dx = y.a.x;
  y.dy = y.a.y;
  y.x_major = fabs(y.dx) >= fabs(y.dy);
  const float gdx = y.dx * f.cell_x, gdy = y.dy * f.cell_y;
  y.length = sqrt(gdx * gdx + gdy * gdy);
  const float bx = y.b.x * f.cell_x, by = y.b.y * f.cell_y;
  y.b_length = sqrt(bx * bx + by * by);
  y.arc_limit = fmin(f.cell_x, f.cell_y) / y.angle;  // distance where the arc reaches a pixel
  y.inv_dx = y.dx != 0.0f ? 1.0f / y.dx : 0.0f;
  y.inv_dy = y.dy != 0.0f ? 1.0f / y.dy : 0.0f;
  y.ax = axis_start(y.dx > 0.0f ? ex + 1.0f : ex - 1.0f, ex, y.dx, y.inv_dx, y.dy);
  y.ay = axis_start(y.dy > 0.0f ? ey + 1.0f : ey - 1.0f, ey, y.dy, y.inv_dy, y.dx);
  y.drop = f.curvature * y.length * y.length;
  // Side b of the wedge across the major axis, where it runs the same way along it.
  const int a_major = y.x_major ? y.a.x : y.a.y, b_major = y.x_major ? y.b.x : y.b.y;
  y.b_along = b_major != 0 && (b_major > 0) == (a_major > 0);
  y.slope_b = y.b_along ? (float)(y.x_major ? y.b.y : y.b.x) / b_major : 0.0f;
  return y;
}

// A ray's bounds over one piece [t0, t1] of it within one cell, where f (the surface's height
// above the eye, curvature taken) runs from f0 to f1 with t^2 coefficient alpha, lip the
// surface's slope bound around the cell: *lo, *hi_ray (along the ray itself) and *hi (for every
// sight line of the wedge) raised where `live`. *lo takes the surface lowered by `forgiven` (at
// least forgiven_rise's of every target the ray settles), so that a target below it is hidden by
// more than the rounding its march forgives. The largest slope
// f / (t D) on the piece is at most its top over the nearest distance (the farthest where the
// top is negative); on the first piece (t0 = 0, f0 = -eye height <= 0) f / t <= (f - f0) / t,
// which is linear in t: at most its value at an end. The widening is lip * angle while t D
// stays within arc_limit; a sight line at a smaller angle delta from the ray needs only lip *
// delta, so the bound over the prefix is a maximum of linear functions of delta, from *hi_ray at
// 0 to *hi at the wedge's angle. For scalars and lane vectors alike.
#define HF_MAX(a, b) ((a) > (b) ? (a) : (b))
#define HFVIS_RAY_BOUNDS(F, I)                                                                              \
  HFVIS_INLINE HFVIS_OVERLOADABLE void ray_bounds(F t0, F t1, F f0, F f1, F alpha, F length, F arc_limit,   \
                                                  F lip, F angle, float forgiven, I live, F* lo, F* hi_ray, \
                                                  F* hi) {                                                  \
    const F span = t1 - t0;                                                                                 \
    /* With a nodata end (f NaN) HF_MAX keeps the other: -INFINITY past a nodata crossing. */               \
    const F top = HF_MAX(HF_MAX(f0, f1), quadratic_bump(f0, f1, alpha * span * span));                      \
    const F rise = (f1 - f0) / t1;                                                                          \
    const F first = f0 > 0.0f ? (F)INFINITY : HF_MAX(rise - alpha * t1, rise) / length;                     \
    F seg_hi = t0 > 0.0f ? native_divide(top, (top >= 0.0f ? t0 : t1) * length) : first;                    \
    const F seg_lo = native_divide(f1 - forgiven, t1 * length);                                             \
    const F widen = t1 * length <= arc_limit ? lip * angle : (F)INFINITY;                                   \
    seg_hi = isnan(seg_hi) ? (F)INFINITY : seg_hi;                                                          \
    *hi_ray = live ? HF_MAX(*hi_ray, seg_hi) : *hi_ray;                                                     \
    /* No bound for the wedge where the widening has none (a nodata cell near, or past the arc */           \
    /* limit), whatever the ray itself meets (-INFINITY in a nodata cell). */                               \
    *hi = live ? HF_MAX(*hi, !(widen < INFINITY) ? (F)INFINITY : seg_hi + widen) : *hi;                     \
    /* a surface point the sight lines pass near */                                                         \
    *lo = (live & !isnan(seg_lo)) ? HF_MAX(*lo, seg_lo - widen) : *lo;                                      \
  }
HFVIS_RAY_BOUNDS(float, int)
#if HFVIS_LANES > 1
HFVIS_RAY_BOUNDS(lane_float, lane_int)
#endif

// Ray r marched alone, event by event (grid-line crossings in order); it settles the targets of
// its wedge (viewshed_rays).
HFVIS_INLINE void one_ray(int r, __global const float* h, Field f, __global const float* lipschitz, int ex_i,
                          int ey_i, float ze, float target_height, float forgiven, int4 box, int rays,
                          __global const int* need, int use_need, float unit, __global uchar* pending,
                          __global float* ray_hi, __global float* out_visible, int accumulate) {
  Ray y = ray_setup(r, rays, f, ex_i, ey_i, box, need, use_need, unit);
  if (!y.ok) return;
  const float ex = ex_i, ey = ey_i;
  const int cells_x = max(f.width - 1, 1);
  float lo = -INFINITY, hi_ray = -INFINITY, hi = -INFINITY;
  float hi_ray_back = INFINITY, hi_back = INFINITY, d_back = 0.0f;  // at the previous major crossing
  float t0 = 0.0f, f0 = h[ey_i * f.width + ex_i] - ze;
  for (;;) {
    const float tx = y.ax.t, ty = y.ay.t;
    const float t1 = hf_min(hf_min(tx, ty), 1.0f);
    const float tm = 0.5f * (t0 + t1);
    const int4 c = cell_of(ex + tm * y.dx, ey + tm * y.dy, f.width, f.height);
    const float s1 = t1 == tx   ? surface_at_crossing(h, f.width, 1, &y.ax, ex_i, ey_i)
                     : t1 == ty ? surface_at_crossing(h, f.width, 0, &y.ay, ex_i, ey_i)
                                : h[(int)y.end.y * f.width + (int)y.end.x];
    const float f1 = (s1 - ze) - y.drop * t1 * t1;
    const float alpha = surface_curve(h, f.width, c, y.dx, y.dy) - y.drop;  // t^2 coefficient of f
    ray_bounds(t0, t1, f0, f1, alpha, y.length, y.arc_limit, lipschitz[c.y * cells_x + c.x], y.angle,
               forgiven, 1, &lo, &hi_ray, &hi);
    const float d_ray = t1 * y.length;
    const int crossed = y.x_major ? tx <= t1 : ty <= t1;  // a grid line of the major axis, at t1
    f0 = f1;
    if (tx <= t1) axis_next(&y.ax, ex, y.dx, y.inv_dx);
    if (ty <= t1) axis_next(&y.ay, ey, y.dy, y.inv_dy);
    t0 = t1;
    // Past a crossing of the major axis the next grid line's targets (the axis now holds that
    // line). Past the ray's end the wedge meets the next line only outside the box or at the next
    // border point, which is not its own.
    if (crossed) {
      const Axis major = y.x_major ? y.ax : y.ay;
      settle_targets(h, f, ex_i, ey_i, ze, target_height, box, y.x_major, 1, (int)major.g, major.q, major.r,
                     major.inv_den, y.b_along, y.slope_b, y.a.x, y.a.y, y.b.x, y.b.y, y.b_length, lo, hi_ray, hi,
                     d_ray, hi_ray_back, hi_back, d_back, pending, ray_hi, out_visible, accumulate);
      hi_ray_back = hi_ray;
      hi_back = hi;
      d_back = d_ray;
    }
    if (t1 >= 1.0f || d_ray > y.reach) break;
  }
}

#if HFVIS_LANES > 1
// Axis (above) in lanes.
typedef struct {
  lane_float g, t, inv_den;
  lane_int q, r, den, dq, dr;
} LaneAxis;

HFVIS_INLINE void lane_axis_put(LaneAxis* v, int l, Axis a) {
  LANE(v->g, l) = a.g, LANE(v->t, l) = a.t, LANE(v->inv_den, l) = a.inv_den;
  ILANE(v->q, l) = a.q, ILANE(v->r, l) = a.r, ILANE(v->den, l) = a.den, ILANE(v->dq, l) = a.dq, ILANE(v->dr, l) = a.dr;
}

// axis_next where `go`.
HFVIS_INLINE void lane_axis_next(LaneAxis* a, float e_along, lane_float d_along, lane_float inv_along, lane_int go) {
  const lane_float g = a->g + sign(d_along);
  const lane_int before = (d_along != 0.0f) & (d_along > 0.0f ? g < e_along + d_along : g > e_along + d_along);
  const lane_float t = before ? (g - e_along) * inv_along : (lane_float)INFINITY;
  lane_int q = a->q + a->dq, r = a->r + a->dr;
  const lane_int carry = r >= a->den;
  r = carry ? r - a->den : r;
  q = carry ? q + 1 : q;
  a->g = go ? g : a->g;
  a->t = go ? t : a->t;
  a->q = go ? q : a->q;
  a->r = go ? r : a->r;
}

// surface_at_crossing in lanes (lanes not `live` read the first height).
HFVIS_INLINE lane_float lane_surface_at_crossing(__global const float* h, int width, int x_axis, const LaneAxis* a,
                                                 int ex, int ey, lane_int live) {
  const lane_int g = convert_int8(a->g);
  const lane_int at = live ? (x_axis ? (ey + a->q) * width + g : g * width + (ex + a->q)) : (lane_int)0;
  const lane_int next = a->r != 0 ? at + (x_axis ? width : 1) : at;
  const lane_float lo = gather(h, at), hi = gather(h, next);
  return a->r == 0 ? lo : lo + (hi - lo) * (convert_float8(a->r) * a->inv_den);
}

// The bounds over the piece [t0, t1] of the lanes' rays (t1 where `live`), from its cell (at the
// piece's middle) and f1 at its end.
HFVIS_INLINE void lane_piece(__global const float* h, Field f, __global const float* lipschitz, float ex,
                             float ey, lane_float dx, lane_float dy, lane_float drop, lane_float length,
                             lane_float arc_limit, lane_float angle, float forgiven, lane_float t0,
                             lane_float t1, lane_float f0, lane_float f1, lane_int live, lane_float* lo,
                             lane_float* hi_ray, lane_float* hi) {
  const lane_float tm = 0.5f * (t0 + t1);
  const lane_int cx = clamp(convert_int8(floor(ex + tm * dx)), 0, f.width > 2 ? f.width - 2 : 0);
  const lane_int cy = clamp(convert_int8(floor(ey + tm * dy)), 0, f.height > 2 ? f.height - 2 : 0);
  const lane_int cz = cx + 1 < f.width ? cx + 1 : cx, cw = cy + 1 < f.height ? cy + 1 : cy;
  const lane_int y0 = live ? cy * f.width : (lane_int)0, y1 = live ? cw * f.width : (lane_int)0;
  const lane_int x0 = live ? cx : (lane_int)0, x1 = live ? cz : (lane_int)0;
  const lane_float twist = gather(h, y0 + x0) - gather(h, y0 + x1) - gather(h, y1 + x0) + gather(h, y1 + x1);
  const lane_float alpha = (dx * dy != 0.0f ? twist * dx * dy : (lane_float)0.0f) - drop;  // t^2 coefficient of f
  const lane_float lip = gather(lipschitz, live ? cy * max(f.width - 1, 1) + cx : (lane_int)0);
  ray_bounds(t0, t1, f0, f1, alpha, length, arc_limit, lip, angle, forgiven, live, lo, hi_ray, hi);
}

// Rays r0 .. r0 + 7 in lanes, column by column (row by row for rays nearer the y axis): one step
// per grid line of the major axis, with the minor axis's crossings before it where there are
// (one at most, as the rays run at most 45 degrees from the major axis, but for a rounding that
// puts the next one just before instead of just after it). Returns 0, marching
// nothing, where the rays to march do not all share the major axis and its direction.
HFVIS_INLINE int rays_in_lanes(int r0, __global const float* h, Field f, __global const float* lipschitz,
                               int ex_i, int ey_i, float ze, float target_height, float forgiven, int4 box,
                               int rays, __global const int* need, int use_need, float unit,
                               __global uchar* pending, __global float* ray_hi, __global float* out_visible,
                               int accumulate) {
  Ray ray[HFVIS_LANES];
  int x_major = -1, forward = 0;
  for (int l = 0; l < HFVIS_LANES; ++l) {
    ray[l] = ray_setup(min(r0 + l, rays - 1), rays, f, ex_i, ey_i, box, need, use_need, unit);
    ray[l].ok = ray[l].ok && r0 + l < rays;
    if (!ray[l].ok) continue;
    const int fwd = (ray[l].x_major ? ray[l].dx : ray[l].dy) > 0.0f;
    if (x_major < 0) x_major = ray[l].x_major, forward = fwd;
    if (ray[l].x_major != x_major || fwd != forward) return 0;
  }
  if (x_major < 0) return 1;  // nothing to march
  const float ex = ex_i, ey = ey_i;
  lane_int live, b_along, a_x, a_y, b_x, b_y;
  lane_float dx, dy, inv_dx, inv_dy, length, angle, arc_limit, drop, reach, h_end, slope_b, b_length;
  LaneAxis ax, ay;
  for (int l = 0; l < HFVIS_LANES; ++l) {
    const Ray y = ray[l];
    ILANE(live, l) = y.ok ? -1 : 0;
    LANE(dx, l) = y.dx, LANE(dy, l) = y.dy, LANE(inv_dx, l) = y.inv_dx, LANE(inv_dy, l) = y.inv_dy;
    LANE(length, l) = y.length, LANE(angle, l) = y.angle, LANE(arc_limit, l) = y.arc_limit;
    LANE(drop, l) = y.drop, LANE(reach, l) = y.reach;
    LANE(h_end, l) = h[(int)y.end.y * f.width + (int)y.end.x];
    ILANE(b_along, l) = y.b_along ? -1 : 0, LANE(slope_b, l) = y.slope_b, LANE(b_length, l) = y.b_length;
    ILANE(a_x, l) = y.a.x, ILANE(a_y, l) = y.a.y, ILANE(b_x, l) = y.b.x, ILANE(b_y, l) = y.b.y;
    lane_axis_put(&ax, l, y.ax);
    lane_axis_put(&ay, l, y.ay);
  }
  lane_float lo = -INFINITY, hi_ray = -INFINITY, hi = -INFINITY;
  lane_float hi_ray_back = INFINITY, hi_back = INFINITY, d_back = 0.0f;
  lane_float t0 = 0.0f, f0 = h[ey_i * f.width + ex_i] - ze;
  LaneAxis* major = x_major ? &ax : &ay;
  LaneAxis* minor = x_major ? &ay : &ax;
  const lane_float d_major = x_major ? dx : dy, d_minor = x_major ? dy : dx;
  const lane_float inv_major = x_major ? inv_dx : inv_dy, inv_minor = x_major ? inv_dy : inv_dx;
  const float e_major = x_major ? ex : ey, e_minor = x_major ? ey : ex;
  while (ANY_LANE(live)) {
    const lane_float t_major = major->t;
    const lane_float t_end = t_major < 1.0f ? t_major : (lane_float)1.0f;  // the next major line, or the end
    const lane_int at_major = t_end == t_major;  // else the end
    const lane_float s_major = lane_surface_at_crossing(h, f.width, x_major, major, ex_i, ey_i, live & at_major);
    const lane_float f_end = ((at_major ? s_major : h_end) - ze) - drop * t_end * t_end;
    // The minor lines' crossings first, where there are: one at most, but for rounding.
    for (lane_int go = live & (minor->t < t_end); ANY_LANE(go); go = live & (minor->t < t_end)) {
      const lane_float t_minor = minor->t;
      const lane_float s_minor = lane_surface_at_crossing(h, f.width, !x_major, minor, ex_i, ey_i, go);
      const lane_float f_minor = (s_minor - ze) - drop * t_minor * t_minor;
      lane_piece(h, f, lipschitz, ex, ey, dx, dy, drop, length, arc_limit, angle, forgiven, t0, t_minor, f0,
                 f_minor, go, &lo, &hi_ray, &hi);
      t0 = go ? t_minor : t0;
      f0 = go ? f_minor : f0;
      lane_axis_next(minor, e_minor, d_minor, inv_minor, go);
    }
    lane_piece(h, f, lipschitz, ex, ey, dx, dy, drop, length, arc_limit, angle, forgiven, t0, t_end, f0,
               f_end, live, &lo, &hi_ray, &hi);
    // A crossing of both axes at once (a grid point) moves both on.
    lane_axis_next(minor, e_minor, d_minor, inv_minor, live & (minor->t <= t_end));
    lane_axis_next(major, e_major, d_major, inv_major, live & at_major);
    t0 = live ? t_end : t0;
    f0 = live ? f_end : f0;
    const lane_float d_ray = t_end * length;
    // Past a crossing of the major axis the next grid line's targets (the axis now holds that
    // line; none past the end, as one_ray says).
    settle_targets(h, f, ex_i, ey_i, ze, target_height, box, x_major, live & at_major, convert_int8(major->g),
                   major->q, major->r, major->inv_den, b_along, slope_b, a_x, a_y, b_x, b_y, b_length, lo, hi_ray,
                   hi, d_ray, hi_ray_back, hi_back, d_back, pending, ray_hi, out_visible, accumulate);
    hi_ray_back = live ? hi_ray : hi_ray_back;
    hi_back = live ? hi : hi_back;
    d_back = live ? d_ray : d_back;
    live = live & at_major & (d_ray <= reach);
  }
  return 1;
}
#endif

// viewshed_rays, one work-item per ray from the eye E to border point r (HFVIS_LANES rays in
// SIMD lanes on a CPU), marched cell by cell. A ray keeps bounds on the largest slope
// (s(t) - ze) / (t D) met so far, widened so that they also bound that of every sight line of
// its wedge (to border point r + 1, at distances the ray has reached): lo <= that slope <= hi.
// The widening is L * angle, L the surface's slope bound around the cell (|s difference| <= L *
// arc between two lines at one distance, arc = distance * angle), valid while the arc stays
// within one pixel of the ray. Each time the ray crosses a grid line of its major axis it
// settles the wedge's targets on the next one (settle_targets).
//
// The wedge of ray r holds the directions v from the eye from border point r's, a (included),
// clockwise to r + 1's, b (excluded): a x v >= 0 > b x v, in integers (a x b > 0: rows grow
// downward, so clockwise on the map is a positive cross product). For an eye strictly inside
// the box these wedges partition the directions around it, so no two rays settle one target;
// an eye on the box's border leaves the wedges along that border empty (a x b <= 0), and rays
// with them settle nothing. The targets no ray settles (those beside the eye, on the border
// line through an eye on it, where a wedge's side b runs against the major axis, or past the
// few grid points a line's test takes) keep ray_hi = INFINITY: viewshed_march marches them
// whole.
//
// The margins of the distance tests (1e-5 relative) take native_sqrt and native_divide within
// a few ulp, as PoCL and the GPU drivers give them; the exact marches use correctly rounded
// operations.
__kernel void viewshed_rays(__global const float* h, Field f, __global const float* lipschitz, int ex_i,
                            int ey_i, float ze, float target_height, float forgiven, int4 box, int rays,
                            __global const int* need, int use_need, float unit, __global uchar* pending,
                            __global float* ray_hi, __global float* out_visible, int accumulate) {
#if HFVIS_LANES == 1
  const int r = get_global_id(0);
  if (r < rays)
    one_ray(r, h, f, lipschitz, ex_i, ey_i, ze, target_height, forgiven, box, rays, need, use_need, unit,
            pending, ray_hi, out_visible, accumulate);
#else
  // Lanes whose rays do not run alike (around a diagonal or a corner of the box) go one by one.
  const int r0 = get_global_id(0) * HFVIS_LANES;
  if (r0 >= rays) return;
  if (!rays_in_lanes(r0, h, f, lipschitz, ex_i, ey_i, ze, target_height, forgiven, box, rays, need, use_need,
                     unit, pending, ray_hi, out_visible, accumulate))
    for (int r = r0; r < min(r0 + HFVIS_LANES, rays); ++r)
      one_ray(r, h, f, lipschitz, ex_i, ey_i, ze, target_height, forgiven, box, rays, need, use_need, unit,
              pending, ray_hi, out_visible, accumulate);
#endif
}

// The culling pyramid's query (ViewshedPyramid in hfvis/viewshed.hpp), one work-item per node of
// one level (level: nodes across, down, first node's index, k: nodes of 2^k x 2^k grid points),
// the coarsest level first: culled[node] = 1 where its parent (in level `parent`, when
// has_parent) is culled, or where for every sector (spans: start, width, radians) that its
// points can see the eye in, the eye lies farther than the sector's d from each of them and below
// its bound (regions: per node and sector, d then the bound at the breakpoints `breaks`) at
// both ends of the range of their distances. The bound is concave, so it is least over that
// range at an end; the curvature term c r^2 is taken at the range's nearer end (farther for
// c < 0). Every comparison that meets a NaN keeps the node.
#define CULL_BREAKS 5
#define CULL_FLOATS (1 + CULL_BREAKS)

inline float cull_bound(__global const float* region, __constant float* breaks, float r) {
  for (int i = 0; i + 1 < CULL_BREAKS; ++i)
    if (r <= breaks[i + 1]) {
      const float a = region[1 + i], b = region[2 + i];
      if (a == b) return a;  // an empty node's FLT_MAX
      return a + (b - a) * ((r - breaks[i]) / (breaks[i + 1] - breaks[i]));
    }
  return NAN;  // past the reach
}

__kernel void viewshed_cull(__global const float* regions, int4 level, int4 parent, int has_parent, int sectors,
                            __constant float2* spans, __constant float* breaks, Field f, float ex, float ey,
                            float ze, __global uchar* culled) {
  const int nx = get_global_id(0), ny = get_global_id(1);
  if (nx >= level.x || ny >= level.y) return;
  const size_t node = (size_t)level.z + (size_t)ny * level.x + nx;
  if (has_parent && culled[(size_t)parent.z + (size_t)(ny >> 1) * parent.x + (nx >> 1)]) {
    culled[node] = 1;
    return;
  }
  const int side = 1 << level.w;
  const int x0 = nx * side, y0 = ny * side;
  const int x1 = min(x0 + side, f.width) - 1, y1 = min(y0 + side, f.height) - 1;
  const float hx = 0.5f * (x1 - x0) * f.cell_x, hy = 0.5f * (y1 - y0) * f.cell_y;
  const float gx = (ex - 0.5f * (x0 + x1)) * f.cell_x, gy = (ey - 0.5f * (y0 + y1)) * f.cell_y;
  const float rc = sqrt(gx * gx + gy * gy), rho = sqrt(hx * hx + hy * hy);
  // The points' distances to the eye, widened past the rounding of these few operations.
  const float r_lo = rc * (1.0f - 1e-5f) - rho * (1.0f + 1e-5f), r_hi = (rc + rho) * (1.0f + 1e-5f);
  int cull = r_lo > 0.0f;
  // The eye's azimuth from the node's points lies within alpha of that from its centre.
  const float alpha = cull ? asin(fmin(1.0f, rho * (1.0f + 1e-5f) / rc)) + 1e-4f : 0.0f;
  const float phi = atan2(gy, gx);
  const float two_pi = 2.0f * M_PI_F;
  const float curve = f.curvature * (f.curvature >= 0.0f ? r_lo * r_lo : r_hi * r_hi);
  const float lhs = ze - curve;
  for (int s = 0; cull && s < sectors; ++s) {
    const float2 span = spans[s];
    float rel = phi - alpha - span.x;  // from the sector's start to the range's, counter-clockwise
    rel -= two_pi * floor(rel / two_pi);
    if (!(rel <= span.y || rel + 2.0f * alpha >= two_pi)) continue;  // the sector is not met
    __global const float* region = regions + (node * sectors + s) * CULL_FLOATS;
    const float b_lo = cull_bound(region, breaks, r_lo), b_hi = cull_bound(region, breaks, r_hi);
    const float bound = b_lo < b_hi ? b_lo : b_hi;  // NaN (past the reach) when either is
    const float margin = 4e-6f * (fabs(ze) + fabs(curve) + fabs(bound) + fabs(region[1])) + 1e-6f;
    cull = !isnan(b_lo) && !isnan(b_hi) && r_lo > region[0] && lhs < bound - margin;
  }
  culled[node] = cull ? 1 : 0;
}

// sight_blocked over [ta, tb], through the pyramid where there is one (top_level >= 1).
inline int march(__global const float* h, __global const float* pyramid, __constant int4* levels, int top_level,
                 Field f, float ex, float ey, float dx, float dy, float ze, float rise, float d2, float target_height,
                 float ta, float tb) {
  return top_level > 0 ? sight_blocked_pyramid(h, pyramid, levels, top_level, f, ex, ey, dx, dy, ze, rise, d2,
                                               target_height, ta, tb, 0)
                       : sight_blocked(h, f, ex, ey, dx, dy, ze, rise, d2, target_height, ta, tb);
}

// viewshed_classify, one work-item per grid point, before the rays: what needs no sight line.
// Writes out_visible 1 / 0 (NaN at nodata; added to it with accumulate, a cumulative viewshed)
// and out_angle (radians; NaN at nodata; only with want_angle) where that settles it, else
// marks the target pending (for the rays, then viewshed_march) with ray_hi = INFINITY (with
// rays_on; without, ray_hi is not read). Settled:
// nodata; targets past max_distance (> 0; the box holds every other), outside the azimuth range
// (compass degrees clockwise from az_from over az_span, when az_on), outside elevation angles
// [el_lo, el_hi] or culled by the pyramid (not visible); the eye's own point (visible).
__kernel void viewshed_classify(__global const float* h, Field f, int ex_i, int ey_i, float ze, float target_height,
                                int4 box, float max_distance, int az_on, float az_from, float az_span, float el_lo,
                                float el_hi, __global const uchar* culled, int4 cull_level,
                                __global float* out_visible, int accumulate, int want_angle,
                                __global float* out_angle, __global uchar* pending, int rays_on,
                                __global float* ray_hi) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= f.width || y >= f.height) return;
  const size_t p = (size_t)y * f.width + x;
  const float ht = h[p];
  if (isnan(ht)) {
    out_visible[p] = NAN;  // accumulated too: nodata stays NaN
    if (want_angle) out_angle[p] = NAN;
    pending[p] = 0;
    return;
  }
  // Culled by the pyramid (cull_level.x > 0), or outside the box (past the maximum distance):
  // hidden.
  const int hidden_at_once =
      (cull_level.x > 0 && culled[(size_t)cull_level.z + (size_t)(y >> cull_level.w) * cull_level.x + (x >> cull_level.w)]) ||
      x < box.x || x > box.z || y < box.y || y > box.w;
  if (hidden_at_once && !want_angle) {
    put_visible(out_visible, p, 0.0f, accumulate);
    pending[p] = 0;
    return;
  }
  const SightLine s = sight_line(h, f, x, y, ex_i, ey_i, ze, target_height);
  int in_range = !(max_distance > 0.0f && s.dist > max_distance);
  if (want_angle || el_lo > -M_PI_2_F || el_hi < M_PI_2_F) {  // a library atan2 costs more than the rest
    const float angle = s.dist > 0.0f ? hf_atan(s.slope) : (s.rise >= 0.0f ? M_PI_2_F : -M_PI_2_F);
    if (want_angle) out_angle[p] = angle;
    in_range = in_range && angle >= el_lo && angle <= el_hi;
  }
  if (az_on && s.dist > 0.0f) {
    const float compass = degrees(atan2(s.dx * f.cell_x, -s.dy * f.cell_y));
    const float from_start = compass - az_from;
    in_range = in_range && from_start - 360.0f * floor(from_start / 360.0f) <= az_span;
  }
  const int hidden = hidden_at_once || !in_range;
  const int settled = hidden || s.dist == 0.0f;
  if (settled) put_visible(out_visible, p, hidden ? 0.0f : 1.0f, accumulate);
  pending[p] = settled ? 0 : 1;
  if (!settled && rays_on) ray_hi[p] = INFINITY;
}

// counts[row]: the pending targets of each row; with offsets[row] (their running sum, from the
// host), viewshed_pending_list writes their indices p in order into list[offsets[row] ...].
__kernel void viewshed_pending_count(__global const uchar* pending, int width, int height, __global uint* counts) {
  const int row = get_global_id(0);
  if (row >= height) return;
  uint n = 0;
  for (int x = 0; x < width; ++x) n += pending[(size_t)row * width + x];
  counts[row] = n;
}

__kernel void viewshed_pending_list(__global const uchar* pending, int width, int height,
                                    __global const uint* offsets, __global uint* list) {
  const int row = get_global_id(0);
  if (row >= height) return;
  uint n = offsets[row];
  for (int x = 0; x < width; ++x)
    if (pending[(size_t)row * width + x]) list[n++] = (uint)(row * width + x);
}

// viewshed_march, one work-item per pending target (list[0 .. count - 1]): where a ray kept an
// upper bound for it (ray_hi finite), an exact march of the sight line past its split distance;
// if that is clear, the bound, and if it does not settle the target a march of the rest;
// elsewhere a march of the whole sight line. Marches skip what the maximum pyramid (levels
// 1 .. top_level; none when top_level = 0) shows to lie below the sight line.
__kernel void viewshed_march(__global const float* h, Field f, int ex_i, int ey_i, float ze, float target_height,
                             int rays_on, __global const float* ray_hi, __global const float* pyramid,
                             __constant int4* levels,
                             int top_level, __global const uint* list, uint count, __global float* out_visible,
                             int accumulate) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  const uint p = list[i];
  const int x = p % f.width, y = p / f.width;
  const SightLine s = sight_line(h, f, x, y, ex_i, ey_i, ze, target_height);
  const float ex = ex_i, ey = ey_i;
  const float hi = rays_on ? ray_hi[p] : INFINITY;
  const float split = s.dist - split_length(f);
  int blocked;
  if (hi < INFINITY && split > 0.0f) {
    const float t_split = native_divide(split, s.dist);
    blocked = sight_blocked(h, f, ex, ey, s.dx, s.dy, ze, s.rise, s.d2, target_height, t_split, 1.0f);
    if (!blocked && !(s.slope >= hi))  // nothing nearer is known to stay below the sight line: march it
      blocked = march(h, pyramid, levels, top_level, f, ex, ey, s.dx, s.dy, ze, s.rise, s.d2, target_height, 0.0f,
                      t_split);
  } else {
    blocked = march(h, pyramid, levels, top_level, f, ex, ey, s.dx, s.dy, ze, s.rise, s.d2, target_height, 0.0f, 1.0f);
  }
  put_visible(out_visible, p, blocked ? 0.0f : 1.0f, accumulate);
}

// viewshed_needed, one work-item per grid point (after the others): out_needed, the height above
// the surface a target there needs to be seen, max(0, target_height + the largest f(t) / t along
// its whole sight line), by a march through the pyramid; 0 at the eye's point, NaN at nodata and
// out of range (past max_distance, outside the field of view or the elevation limits).
__kernel void viewshed_needed(__global const float* h, Field f, int ex_i, int ey_i, float ze, float target_height,
                              float max_distance, int az_on, float az_from, float az_span, float el_lo, float el_hi,
                              __global const float* pyramid, __constant int4* levels, int top_level,
                              __global float* out_needed) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= f.width || y >= f.height) return;
  const size_t p = (size_t)y * f.width + x;
  const float ht = h[p];
  const float dx = x - ex_i, dy = y - ey_i;
  const float gdx = dx * f.cell_x, gdy = dy * f.cell_y;
  const float d2 = gdx * gdx + gdy * gdy, dist = sqrt(d2);
  const float rise = (ht + target_height - f.curvature * d2) - ze;
  int in_range = !isnan(ht) && !(max_distance > 0.0f && dist > max_distance);
  if (el_lo > -M_PI_2_F || el_hi < M_PI_2_F) {
    const float angle = dist > 0.0f ? hf_atan(rise / dist) : (rise >= 0.0f ? M_PI_2_F : -M_PI_2_F);
    in_range = in_range && angle >= el_lo && angle <= el_hi;
  }
  if (az_on && dist > 0.0f) {
    const float from_start = degrees(atan2(gdx, -gdy)) - az_from;
    in_range = in_range && from_start - 360.0f * floor(from_start / 360.0f) <= az_span;
  }
  if (!in_range) {
    out_needed[p] = NAN;
    return;
  }
  if (dist == 0.0f) {
    out_needed[p] = 0.0f;
    return;
  }
  float excess = -INFINITY;
  sight_blocked_pyramid(h, pyramid, levels, top_level, f, ex_i, ey_i, dx, dy, ze, rise, d2, target_height, 0.0f, 1.0f,
                        &excess);
  float needed = hf_max(0.0f, target_height + excess);
  // 0 where a target on the surface is seen, its sight line grazing within the rounding forgiven
  // (on a tilted plane the exact need is rounding noise).
  if (needed > 0.0f && !sight_blocked_pyramid(h, pyramid, levels, top_level, f, ex_i, ey_i, dx, dy, ze,
                                              (ht - f.curvature * d2) - ze, d2, 0.0f, 0.0f, 1.0f, 0))
    needed = 0.0f;
  out_needed[p] = needed;
}
