// viewshed.cl: what one observer sees on the bilinear surface (computeViewshed in
// src/viewshed.cpp; the method is described in hfvis/viewshed.hpp).
//
// Coordinates are pixels (column x, row y); heights are z-scaled and NaN at nodata. A sight
// line runs from the eye E (a grid point, height ze) to the target T (a grid point, height
// zt): point t in [0, 1] lies over E + t (T - E), at ground distance t D, its sight line at
// ze + t (zt - ze). The surface there, lowered for the Earth's curvature, is
// s(t) = h(E + t (T - E)) - c (t D)^2. Within one cell the bilinear surface along the line is
// a quadratic in t, so the test "does s rise strictly above the sight line" is decided per cell
// from the two ends and the vertex. A cell with a nodata corner has no surface.
//
// Three kernels: viewshed_lipschitz (a bound on the surface's slope around each cell),
// viewshed_rays (one work-item per ray from E to a point of the box's border: bounds on the
// largest elevation slope met within each distance), viewshed_targets (one work-item per
// target: the bounds of the two rays around its sight line decide it, or an exact march does).
#pragma OPENCL FP_CONTRACT OFF

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
  const int cx = clamp((int)floor(x), 0, max(width - 2, 0));
  const int cy = clamp((int)floor(y), 0, max(height - 2, 0));
  return (int4)(cx, cy, min(cx + 1, width - 1), min(cy + 1, height - 1));
}

// The twist of a cell (h00 - h10 - h01 + h11): the t^2 coefficient of the surface along a
// line is twist * dx * dy.
inline float cell_twist(__global const float* h, int width, int4 c) {
  return h[c.y * width + c.x] - h[c.y * width + c.z] - h[c.w * width + c.x] + h[c.w * width + c.z];
}

// The largest value on [0, 1] of the quadratic with ends f0, f1 and t^2 coefficient a (in the
// segment's own parameter), or -INFINITY where it stays at or below its ends' larger one.
inline float quadratic_bump(float f0, float f1, float a) {
  if (!(a < 0.0f)) return -INFINITY;
  const float bump = -a;  // f(s) = f0 + (f1 - f0) s + bump s (1 - s)
  const float s = 0.5f + (f1 - f0) / (2.0f * bump);
  if (!(s > 0.0f && s < 1.0f)) return -INFINITY;
  return f0 + (f1 - f0) * s + bump * s * (1.0f - s);
}

// The parameter t where a line from e (along d, 1 / d = inv) crosses grid line g, or INFINITY when
// g is not strictly before the line's end e + d: a crossing at the end itself would be a
// rounded copy of t = 1.
inline float crossing(float g, float e, float d, float inv) {
  return (d > 0.0f ? g < e + d : g > e + d) ? (g - e) * inv : INFINITY;
}

// The surface where the line from grid point (ex, ey) to (ex + dx, ey + dy) crosses column line
// gx: the linear interpolation between the two heights of that line around the crossing,
// whose position is found in integers (so a crossing at a grid point takes that point's height
// exactly). A point of an edge whose two heights are valid is surface even where the cells
// beside it are not. With the roles of x and y swapped (and `stride` 1 / width), a row line.
inline float surface_on_grid_line(__global const float* h, int width, int g, int e_along, int e_across,
                                  int d_along, int d_across, int stride_along, int stride_across) {
  long num = (long)(g - e_along) * d_across, den = d_along;  // across = e_across + num / den
  if (den < 0) num = -num, den = -den;
  long q = num / den, r = num % den;
  if (r < 0) q -= 1, r += den;
  const size_t at = (size_t)g * stride_along + (size_t)(e_across + q) * stride_across;
  if (r == 0) return h[at];
  const float a = h[at], b = h[at + stride_across];
  return a + (b - a) * ((float)r / (float)den);
}

// The surface at the crossing at t1: of column line gx where t1 == tx, else of row line gy.
inline float surface_at_crossing(__global const float* h, int width, float t1, float tx, int gx, int gy, int ex,
                                 int ey, int dx, int dy) {
  return t1 == tx ? surface_on_grid_line(h, width, gx, ex, ey, dx, dy, 1, width)
                  : surface_on_grid_line(h, width, gy, ey, ex, dy, dx, width, 1);
}

// March of the sight line from E (ex, ey) along (dx, dy) over t in [ta, tb] (0 <= ta < tb <= 1),
// cell by cell. rise: zt - ze; d2: D^2; target_height: the sight line's height above the surface
// at t = 1, taken as it is rather than as the rounded difference of the two. Returns 1 where the
// surface rises strictly above the sight line somewhere on [ta, tb]: at a grid-line crossing,
// or inside a cell without nodata at the top of its quadratic.
int sight_blocked(__global const float* h, Field f, float ex, float ey, float dx, float dy, float ze, float rise,
                  float d2, float target_height, float ta, float tb) {
  const float inv_dx = dx != 0.0f ? 1.0f / dx : 0.0f, inv_dy = dy != 0.0f ? 1.0f / dy : 0.0f;
  const float sx = sign(dx), sy = sign(dy);
  // The next grid lines crossed after ta.
  float gx = dx > 0.0f ? floor(ex + ta * dx) + 1.0f : ceil(ex + ta * dx) - 1.0f;
  float gy = dy > 0.0f ? floor(ey + ta * dy) + 1.0f : ceil(ey + ta * dy) - 1.0f;
  float tx = crossing(gx, ex, dx, inv_dx), ty = crossing(gy, ey, dy, inv_dy);
  const float drop = f.curvature * d2;
  float t0 = ta, f0 = NAN;
  if (ta == 0.0f) f0 = h[(int)ey * f.width + (int)ex] - ze;
  while (t0 < tb) {
    const float t1 = fmin(fmin(tx, ty), tb);
    const float tm = 0.5f * (t0 + t1);
    const int4 c = cell_of(ex + tm * dx, ey + tm * dy, f.width, f.height);
    float s1;
    if (t1 < tb) {
      s1 = surface_at_crossing(h, f.width, t1, tx, (int)gx, (int)gy, (int)ex, (int)ey, (int)dx, (int)dy);
    } else {
      s1 = sample_cell(h, f.width, c.x, c.y, c.z, c.w, ex + t1 * dx - c.x, ey + t1 * dy - c.y);
    }
    const float f1 = t1 == 1.0f ? (isnan(s1) ? NAN : -target_height) : (s1 - ze) - t1 * rise - drop * t1 * t1;
    if (isnan(f0)) {  // the start of a march past the eye
      const float s0 = sample_cell(h, f.width, c.x, c.y, c.z, c.w, ex + t0 * dx - c.x, ey + t0 * dy - c.y);
      f0 = (s0 - ze) - t0 * rise - drop * t0 * t0;
    }
    const float span = t1 - t0;
    const float a = (cell_twist(h, f.width, c) * dx * dy - drop) * span * span;
    if (f0 > 0.0f || f1 > 0.0f || quadratic_bump(f0, f1, a) > 0.0f) return 1;
    f0 = f1;
    if (tx <= t1) gx += sx, tx = crossing(gx, ex, dx, inv_dx);
    if (ty <= t1) gy += sy, ty = crossing(gy, ey, dy, inv_dy);
    t0 = t1;
  }
  return 0;
}

// lipschitz[cell]: a bound on the surface's ground slope |grad h| anywhere in the 3 x 3 cells
// around it (cells past the field left out); INFINITY where one of them has a nodata corner.
// Cells are indexed by their corner (x, y), x < max(width - 1, 1), y < max(height - 1, 1).
__kernel void viewshed_lipschitz(__global const float* h, Field f, __global float* lipschitz) {
  const int x = get_global_id(0), y = get_global_id(1);
  const int cells_x = max(f.width - 1, 1), cells_y = max(f.height - 1, 1);
  if (x >= cells_x || y >= cells_y) return;
  float bound = 0.0f;
  for (int j = max(y - 1, 0); j <= min(y + 1, cells_y - 1); ++j)
    for (int i = max(x - 1, 0); i <= min(x + 1, cells_x - 1); ++i) {
      const int i1 = min(i + 1, f.width - 1), j1 = min(j + 1, f.height - 1);
      const float h00 = h[j * f.width + i], h10 = h[j * f.width + i1];
      const float h01 = h[j1 * f.width + i], h11 = h[j1 * f.width + i1];
      if (!(isfinite(h00) && isfinite(h10) && isfinite(h01) && isfinite(h11))) {
        bound = INFINITY;
        continue;
      }
      const float gx = fmax(fabs(h10 - h00), fabs(h11 - h01)) / f.cell_x;
      const float gy = fmax(fabs(h01 - h00), fabs(h11 - h10)) / f.cell_y;
      bound = fmax(bound, sqrt(gx * gx + gy * gy));
    }
  lipschitz[y * cells_x + x] = bound * 1.0001f;  // rounding of the bound itself
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
  const float lx = dx > 0.0f ? (box.z - ex) / dx : dx < 0.0f ? (box.x - ex) / dx : INFINITY;
  const float ly = dy > 0.0f ? (box.w - ey) / dy : dy < 0.0f ? (box.y - ey) / dy : INFINITY;
  if (lx <= ly) {
    const float y = clamp(ey + lx * dy, (float)box.y, (float)box.w);
    return dx > 0.0f ? w1 + (y - box.y) : 2 * w1 + h1 + (box.w - y);
  }
  const float x = clamp(ex + ly * dx, (float)box.x, (float)box.z);
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

// Index of entry q (0-based) of ray r in the bounds buffer: ray-major (each ray's entries
// together, from offsets[r]) or step-major (entry q of every ray together, rays apart by 1).
inline size_t bound_index(__global const uint* offsets, int rays, int ray_major, int r, int q) {
  return ray_major ? (size_t)offsets[r] + q : (size_t)q * rays + r;
}

// Ray r from E to border point r, marched cell by cell. Entry q (q = 0 .. count - 1, count =
// offsets[r + 1] - offsets[r]) bounds the largest slope (s(t) - ze) / (t D) met on the ray within
// ground distance (q + 1) * spacing, widened so that it also bounds that of every sight line
// within the angle to the next border point on either side: (lo, hi) with lo <= that slope <= hi.
// The widening is L * angle, L the surface's slope bound around the cell
// (|s difference| <= L * arc between two lines at one distance, arc = distance * angle), valid
// while the arc stays within one pixel of the ray.
__kernel void viewshed_rays(__global const float* h, Field f, __global const float* lipschitz, float ex, float ey,
                            float ze, int4 box, int rays, __global const uint* offsets, int ray_major, float spacing,
                            __global float2* bounds) {
  const int r = get_global_id(0);
  if (r >= rays) return;
  const int count = offsets[r + 1] - offsets[r];
  if (count <= 0) return;
  const float angle = fmax(ray_angle(ex, ey, (r + rays - 1) % rays, r, box, f), ray_angle(ex, ey, r, (r + 1) % rays, box, f));
  const float2 end = border_point(r, box);
  const float dx = end.x - ex, dy = end.y - ey;
  const float gdx = dx * f.cell_x, gdy = dy * f.cell_y;
  const float length = sqrt(gdx * gdx + gdy * gdy);
  const float inv_length = 1.0f / length;
  const float arc_limit = fmin(f.cell_x, f.cell_y) / angle;  // distance where the arc reaches a pixel
  const int cells_x = max(f.width - 1, 1);
  const float inv_dx = dx != 0.0f ? 1.0f / dx : 0.0f, inv_dy = dy != 0.0f ? 1.0f / dy : 0.0f;
  const float sx = sign(dx), sy = sign(dy);
  float gx = dx > 0.0f ? ex + 1.0f : ex - 1.0f;
  float gy = dy > 0.0f ? ey + 1.0f : ey - 1.0f;
  float tx = crossing(gx, ex, dx, inv_dx), ty = crossing(gy, ey, dy, inv_dy);
  const float drop = f.curvature * length * length;
  float lo = -INFINITY, hi = -INFINITY;
  float t0 = 0.0f, f0 = h[(int)ey * f.width + (int)ex] - ze;
  int q = 0;
  float next = spacing * inv_length;  // t of entry q's distance
  while (q < count) {
    const float t1 = fmin(fmin(tx, ty), 1.0f);
    const float tm = 0.5f * (t0 + t1);
    const int4 c = cell_of(ex + tm * dx, ey + tm * dy, f.width, f.height);
    const float s1 = t1 < 1.0f ? surface_at_crossing(h, f.width, t1, tx, (int)gx, (int)gy, (int)ex, (int)ey, (int)dx, (int)dy)
                               : h[(int)end.y * f.width + (int)end.x];
    const float f1 = (s1 - ze) - drop * t1 * t1;  // height above the eye, curvature taken
    const float span = t1 - t0;
    const float alpha = cell_twist(h, f.width, c) * dx * dy - drop;  // t^2 coefficient of f
    const float top = fmax(fmax(f0, f1), quadratic_bump(f0, f1, alpha * span * span));
    // The largest slope f / (t D) on the segment is at most its top over the nearest distance
    // (the farthest where the top is negative). On the first segment (t0 = 0, f0 = -eye
    // height <= 0) f / t <= (f - f0) / t, which is linear in t: at most its value at an end.
    float seg_hi;
    if (t0 > 0.0f)
      seg_hi = top >= 0.0f ? top / (t0 * length) : top / (t1 * length);
    else if (f0 > 0.0f)
      seg_hi = INFINITY;  // the eye below the surface
    else
      seg_hi = fmax((f1 - f0) / t1 - alpha * t1, (f1 - f0) / t1) / length;
    const float seg_lo = f1 / (t1 * length);
    const float widen = t1 * length <= arc_limit ? lipschitz[c.y * cells_x + c.x] * angle : INFINITY;
    seg_hi = isnan(seg_hi) || isnan(widen) ? INFINITY : seg_hi + widen;
    hi = fmax(hi, seg_hi);
    while (q < count && next <= t1) {
      bounds[bound_index(offsets, rays, ray_major, r, q)] = (float2)(lo, hi);
      ++q;
      next = (q + 1) * spacing * inv_length;
    }
    if (!isnan(seg_lo)) lo = fmax(lo, seg_lo - widen);  // a surface point the sight lines pass near
    f0 = f1;
    if (tx <= t1) gx += sx, tx = crossing(gx, ex, dx, inv_dx);
    if (ty <= t1) gy += sy, ty = crossing(gy, ey, dy, inv_dy);
    t0 = t1;
    if (t1 >= 1.0f) break;
  }
  for (; q < count; ++q) bounds[bound_index(offsets, rays, ray_major, r, q)] = (float2)(lo, INFINITY);
}

inline void put_visible(__global float* out, size_t p, float v, int accumulate) {
  if (accumulate)
    out[p] += v;
  else
    out[p] = v;
}

// One target per work-item over the field: out_visible 1 / 0 (NaN at nodata; added to it with
// accumulate, a cumulative viewshed), out_angle the target's elevation angle from the eye
// (radians; NaN at nodata; only with want_angle). Targets past max_distance (> 0; the box holds
// every other), outside the azimuth range (compass degrees clockwise from az_from over
// az_span, when az_on), or outside elevation angles [el_lo, el_hi] are not visible. rays = 0:
// every target is marched; else the bounds of the rays (see viewshed_rays) decide what they can.
__kernel void viewshed_targets(__global const float* h, Field f, int ex_i, int ey_i, float ze, float target_height,
                               int4 box, float max_distance, int az_on, float az_from, float az_span, float el_lo,
                               float el_hi, int rays, __global const uint* offsets, int ray_major, float spacing,
                               __global const float2* bounds, __global float* out_visible, int accumulate,
                               int want_angle, __global float* out_angle) {
  const int x = get_global_id(0), y = get_global_id(1);
  if (x >= f.width || y >= f.height) return;
  const size_t p = (size_t)y * f.width + x;
  const float ht = h[p];
  if (isnan(ht)) {
    out_visible[p] = NAN;  // accumulated too: nodata stays NaN
    if (want_angle) out_angle[p] = NAN;
    return;
  }
  const float ex = ex_i, ey = ey_i;
  const float dx = x - ex_i, dy = y - ey_i;
  const float gdx = dx * f.cell_x, gdy = dy * f.cell_y;
  const float d2 = gdx * gdx + gdy * gdy;
  const float dist = sqrt(d2);
  const float zt = ht + target_height - f.curvature * d2;
  const float rise = zt - ze;
  const float angle = dist > 0.0f ? atan2(rise, dist) : (rise >= 0.0f ? M_PI_2_F : -M_PI_2_F);
  if (want_angle) out_angle[p] = angle;
  int in_range = !(max_distance > 0.0f && dist > max_distance) && angle >= el_lo && angle <= el_hi;
  if (az_on && dist > 0.0f) {
    const float compass = degrees(atan2(gdx, -gdy));
    const float from_start = compass - az_from;
    in_range = in_range && from_start - 360.0f * floor(from_start / 360.0f) <= az_span;
  }
  if (!in_range) {
    put_visible(out_visible, p, 0.0f, accumulate);
    return;
  }
  if (dist == 0.0f) {
    put_visible(out_visible, p, 1.0f, accumulate);
    return;
  }
  if (rays > 0) {
    const float slope = rise / dist;
    const int q = (int)floor((dist - 1.5f * fmax(f.cell_x, f.cell_y)) / spacing) - 1;  // entry q: within (q + 1) spacing
    if (q >= 0) {
      const float s = border_position(ex, ey, dx, dy, box);
      const int a = ((int)floor(s)) % rays, b = (a + 1) % rays;
      if (q < (int)(offsets[a + 1] - offsets[a]) && q < (int)(offsets[b + 1] - offsets[b])) {
        const float2 ba = bounds[bound_index(offsets, rays, ray_major, a, q)];
        const float2 bb = bounds[bound_index(offsets, rays, ray_major, b, q)];
        if (slope < fmax(ba.x, bb.x)) {  // something nearer rises above the sight line
          put_visible(out_visible, p, 0.0f, accumulate);
          return;
        }
        const float t_split = (q + 1) * spacing / dist;
        if (sight_blocked(h, f, ex, ey, dx, dy, ze, rise, d2, target_height, t_split, 1.0f)) {
          put_visible(out_visible, p, 0.0f, accumulate);
          return;
        }
        if (slope >= fmin(ba.y, bb.y)) {  // nothing nearer rises above it
          put_visible(out_visible, p, 1.0f, accumulate);
          return;
        }
        // Undecided: march the rest.
        put_visible(out_visible, p, sight_blocked(h, f, ex, ey, dx, dy, ze, rise, d2, target_height, 0.0f, t_split) ? 0.0f : 1.0f,
                    accumulate);
        return;
      }
    }
  }
  put_visible(out_visible, p, sight_blocked(h, f, ex, ey, dx, dy, ze, rise, d2, target_height, 0.0f, 1.0f) ? 0.0f : 1.0f, accumulate);
}
