// region_visibility.cl: which source samples each receiver sees (computeRegionVisibility and
// computeRegionPairVisibility in src/ops/region_visibility.cpp; the contract in
// hfvis/region_visibility.hpp). One work-item per receiver: it places its receiver, then per word
// of 32 source samples places them, marches each pair (shared/region_visibility_sight.cl; with a
// culling pyramid, `levels` > 0, the march leaps over the blocks of cells far below the segment,
// and each sight line is tried first against the cell that hid the last hidden one, or the cell
// at the same fraction of its own line; after a clear line, the stretches near both ends that the
// per-end tables of region_end_tables certify clear are skipped: `certify_sources`, the shared
// samples' tables, `certify_receivers`, a pair's receivers') and writes the word, so no two
// work-items write one word and no atomics are needed.
//
// Receivers are the grid points (`pixel_receivers`) or the samples of a second region (the
// table `receivers`, stream 0). Shared source samples (stream 0) come placed by the host
// (`source_points`, x, y, z each, by the same region_sample); decorrelated ones are placed here. The words
// are stored receiver-major (word w of receiver r at r * words + w: a work-item's words contiguous, for CPUs)
// or word-major (w * count + r: neighbouring work-items write neighbouring words, for GPUs), as the context's
// line layout. The host launches the receivers in chunks from `first`, to bound each launch's time.
#pragma OPENCL FP_CONTRACT OFF

#include "shared/region_visibility_sight.cl"

typedef struct {
  int width, height;     // the field
  float cell_x, cell_y;  // ground units per pixel
  float curvature;       // c of the drop c d^2
  float max_d2;          // the largest squared ground distance of a visible pair; 0 = any
} RegionDeviceField;

// The cells around the receiver's point, each side, that its sight lines march exactly when the
// shaft to a word's samples is shown clear beyond them (region_shaft_clear).
#define REGION_NEAR_CELLS 2

// The wedge from the receiver (xr, yr) over the samples' box [sx0, sx1] x [sy0, sy1]: its two
// edges, toward the box's corners most counter-clockwise (wedge[0], wedge[1]) and most clockwise
// (wedge[2], wedge[3]) seen from the receiver; 0 (no wedge) when the receiver lies in the box.
// The corners are ordered by their angle from the direction to the box's centre, taken as a
// pseudo-angle (monotone over the whole turn): a receiver just outside the box sees it over
// nearly half a turn, where the corners lie more than a quarter turn from the centre's direction
// and the sine of that angle (what this took before) no longer orders them, so the wedge left out
// blocks that lines to the samples cross.
int region_wedge(float xr, float yr, float sx0, float sy0, float sx1, float sy1, float* wedge) {
  if (!(xr < sx0 || xr > sx1 || yr < sy0 || yr > sy1)) return 0;
  const float cx = 0.5f * (sx0 + sx1) - xr, cy = 0.5f * (sy0 + sy1) - yr;
  float most = -INFINITY, least = INFINITY;
  for (int c = 0; c < 4; ++c) {
    const float vx = (c & 1 ? sx1 : sx0) - xr, vy = (c & 2 ? sy1 : sy0) - yr;
    // (counter-clockwise from the centre's direction: 0 .. 2 one way, -2 .. 0 the other)
    const float p = region_pseudo_angle(cx * vx + cy * vy, cx * vy - cy * vx);
    const float angle = p > 2.0f ? p - 4.0f : p;
    if (angle > most) most = angle, wedge[0] = vx, wedge[1] = vy;
    if (angle < least) least = angle, wedge[2] = vx, wedge[3] = vy;
  }
  return 1;
}

// Whether the box [x0, x1] x [y0, y1] lies wholly beyond one of the wedge's edges, by more than
// a relative 1e-5 (the marches' positions round).
int region_outside_wedge(float xr, float yr, const float* wedge, float x0, float y0, float x1, float y1) {
  int left = 0, right = 0;
  const float lsize = fabs(wedge[0]) + fabs(wedge[1]), rsize = fabs(wedge[2]) + fabs(wedge[3]);
  for (int c = 0; c < 4; ++c) {
    const float qx = (c & 1 ? x1 : x0) - xr, qy = (c & 2 ? y1 : y0) - yr, qsize = fabs(qx) + fabs(qy);
    left += wedge[0] * qy - wedge[1] * qx > 1e-5f * lsize * qsize;
    right += wedge[2] * qy - wedge[3] * qx < -1e-5f * rsize * qsize;
  }
  return left == 4 || right == 4;
}

// A depth-first walk over the pyramid's blocks that may reach a shaft from the receiver (xr, yr):
// the blocks meeting the footprint (the box fx0, fy0 .. fx1, fy1 around the receiver and the far
// ends) and, when `wedged`, not wholly beyond one of the wedge's edges (region_wedge). The shaft
// test (region_shaft_clear) and the bitmask scatter (region_bitmask_bits) both walk the blocks
// this way; each decides per block whether to descend (region_walk_descend).
#define REGION_WALK_STACK 64
typedef struct {
  int k[REGION_WALK_STACK], x[REGION_WALK_STACK], y[REGION_WALK_STACK];
  int top;
  float xr, yr, fx0, fy0, fx1, fy1;
  int wedged;
  float wedge[4];
} RegionBlockWalk;

// A walk from (xr, yr) over the footprint of the far ends' box [sx0, sx1] x [sy0, sy1], nothing
// pushed yet.
inline void region_walk_init(RegionBlockWalk* w, float xr, float yr, float sx0, float sy0, float sx1,
                             float sy1) {
  w->top = 0;
  w->xr = xr, w->yr = yr;
  w->fx0 = fmin(xr, sx0), w->fx1 = fmax(xr, sx1), w->fy0 = fmin(yr, sy0), w->fy1 = fmax(yr, sy1);
  w->wedged = region_wedge(xr, yr, sx0, sy0, sx1, sy1, w->wedge);
}

// Pushes the top level's blocks (`levels` > 0); 0 when the stack cannot hold them (the caller
// then decides nothing from the walk).
inline int region_walk_start(RegionBlockWalk* w, int levels, int width, int height) {
  const int last = levels - 1;
  for (int by = 0; by < region_cull_width(height, last); ++by)
    for (int bx = 0; bx < region_cull_width(width, last); ++bx) {
      if (w->top == REGION_WALK_STACK) return 0;
      w->k[w->top] = last, w->x[w->top] = bx, w->y[w->top] = by, ++w->top;
    }
  return 1;
}

// The next block of the walk: its level *k and indices (*bx, *by), its box's first corner (*x0,
// *y0), its ground distance from the receiver (*near) and its pyramid value (*highest); blocks
// wholly inside `skip` (x0, y0, x1, y1; 0: none) are passed over. 0 when the walk is done.
inline int region_walk_next(RegionBlockWalk* w, __global const float* pyramid, RegionDeviceField f,
                            const float* skip, int* k, int* bx, int* by, float* x0, float* y0, float* near,
                            float* highest) {
  while (w->top > 0) {
    --w->top;
    const int kk = w->k[w->top], ix = w->x[w->top], iy = w->y[w->top];
    const float bx0 = (float)(ix << kk), by0 = (float)(iy << kk);
    const float bx1 = fmin((float)((ix + 1) << kk), (float)(f.width - 1)),
                by1 = fmin((float)((iy + 1) << kk), (float)(f.height - 1));
    if (bx1 < w->fx0 || bx0 > w->fx1 || by1 < w->fy0 || by0 > w->fy1) continue;
    if (skip && bx0 >= skip[0] && bx1 <= skip[2] && by0 >= skip[1] && by1 <= skip[3]) continue;
    if (w->wedged && region_outside_wedge(w->xr, w->yr, w->wedge, bx0, by0, bx1, by1)) continue;
    const float ddx = fmax(0.0f, fmax(bx0 - w->xr, w->xr - bx1)) * f.cell_x,
                ddy = fmax(0.0f, fmax(by0 - w->yr, w->yr - by1)) * f.cell_y;
    *near = sqrt(ddx * ddx + ddy * ddy);
    *highest = pyramid[region_cull_offset(f.width, f.height, kk) + iy * region_cull_width(f.width, kk) + ix];
    *k = kk, *bx = ix, *by = iy, *x0 = bx0, *y0 = by0;
    return 1;
  }
  return 0;
}

// Pushes the children of block (k > 0, bx, by) that lie inside their level, the one nearest the
// receiver last, so visited first (near cells decide the most); 0 when the stack cannot hold them.
inline int region_walk_descend(RegionBlockWalk* w, RegionDeviceField f, int k, int bx, int by) {
  if (w->top + 4 > REGION_WALK_STACK) return 0;
  const int child = 1 << (k - 1);
  const int nearest =
      (w->xr >= (float)((2 * bx + 1) * child)) | (w->yr >= (float)((2 * by + 1) * child)) << 1;
  for (int c = 3; c >= 0; --c) {
    const int q = c ^ nearest, cx = 2 * bx + (q & 1), cy = 2 * by + (q >> 1);
    if (cx < region_cull_width(f.width, k - 1) && cy < region_cull_width(f.height, k - 1))
      w->k[w->top] = k - 1, w->x[w->top] = cx, w->y[w->top] = cy, ++w->top;
  }
  return 1;
}

// Whether every segment from the receiver (xr, yr, zr) to the n samples (xs, ys, zs) is clear of
// the surface outside the box of grid lines around the receiver (REGION_NEAR_CELLS cells each
// side of its point, *box: x0, y0, x1, y1), by the margins of the culled march: every block of
// the pyramid over the shaft's footprint (the wedge from the receiver to the samples' bounding
// box) lies below the lowest the shaft can be over it (the receiver's height plus the smallest
// slope to a sample times the block's ground distance) by the march's clearance. Blocks within
// the box are left to the segments' own marches; 0 when a cell outside it may reach the shaft.
int region_shaft_clear(__global const float* h, __global const float* pyramid, int levels, float margin,
                       RegionDeviceField f, float xr, float yr, float zr, const float* xs, const float* ys,
                       const float* zs, int n, float* box) {
  float slope = INFINITY, far = 0.0f, zabs = fabs(zr);
  float sx0 = INFINITY, sy0 = INFINITY, sx1 = -INFINITY, sy1 = -INFINITY;
  for (int i = 0; i < n; ++i) {
    const float gx = (xs[i] - xr) * f.cell_x, gy = (ys[i] - yr) * f.cell_y, d = sqrt(gx * gx + gy * gy);
    if (!(d > 0.0f) || isnan(zs[i])) return 0;
    slope = fmin(slope, (zs[i] - zr) / d);
    far = fmax(far, d);
    zabs = fmax(zabs, fabs(zs[i]));
    sx0 = fmin(sx0, xs[i]), sx1 = fmax(sx1, xs[i]), sy0 = fmin(sy0, ys[i]), sy1 = fmax(sy1, ys[i]);
  }
  // The march's clearance for the longest segment, its slope's rounding allowed for (1e-5
  // relative, as the rest).
  const float cdd = f.curvature * far * far;
  const float clearance =
      margin + 1e-5f * (4.0f * zabs + fabs(cdd) + fabs(slope) * far) + fmax(cdd, 0.0f) * 0.25f;
  const float rx = floor(xr), ry = floor(yr);
  box[0] = fmax(0.0f, rx - REGION_NEAR_CELLS),
  box[2] = fmin((float)(f.width - 1), ceil(xr) + REGION_NEAR_CELLS);
  box[1] = fmax(0.0f, ry - REGION_NEAR_CELLS),
  box[3] = fmin((float)(f.height - 1), ceil(yr) + REGION_NEAR_CELLS);
  // The footprint: its bounding box, and (receiver outside the samples' box) the wedge's two
  // edges, toward the samples' corners most counter-clockwise and most clockwise.
  RegionBlockWalk walk;
  region_walk_init(&walk, xr, yr, sx0, sy0, sx1, sy1);
  if (!region_walk_start(&walk, levels, f.width, f.height)) return 0;
  int k, bx, by;
  float x0, y0, near, highest;
  while (region_walk_next(&walk, pyramid, f, box, &k, &bx, &by, &x0, &y0, &near, &highest)) {
    const float lowest = zr + slope * (slope >= 0.0f ? near : far);
    if (highest + clearance < lowest) continue;
    if (k == 0 || !region_walk_descend(&walk, f, k, bx, by)) return 0;
  }
  return 1;
}

// The cell to try against the sight line from the receiver (xr, yr, zr) to (xs, ys, zs) when the
// cell that hid the last hidden line does not hide it: the cell at the same fraction `along` of
// the new line from the receiver as that one was of its line, or up to two cells before or after
// it, the first that region_cull_hides shows hiding it (lines to neighbouring samples cross a
// ridge or a wall at about the same fraction, in neighbouring cells; two cells either side rather
// than one: 7 - 19 % less CPU time on the city DSM's pairs and up to 8 % on the fractal's hidden
// ones, the clear pair even, three cost it 1 - 3 %: bench/report/region_visibility.md); -1 when
// none does.
int region_hider_along(__global const float* h, RegionDeviceField f, float margin, float gradient, int finite_field,
                       float along, int tried, float xr, float yr, float zr, float xs, float ys, float zs) {
  const float dx = xs - xr, dy = ys - yr, pixels = fmax(fabs(dx), fabs(dy));
  if (!(pixels > 0.0f)) return -1;
  for (int k = -2; k <= 2; ++k) {
    const float t = along + (float)k / pixels;
    if (!(t > 0.0f && t < 1.0f)) continue;
    const int cell = region_cell_at(f.width, f.height, xr + t * dx, yr + t * dy);
    if (cell >= 0 && cell != tried &&
        region_cull_hides(h, f.width, f.height, f.cell_x, f.cell_y, f.curvature, f.max_d2, margin, gradient,
                          finite_field, cell, xs, ys, zs, xr, yr, zr))
      return cell;
  }
  return -1;
}

// The fraction of the sight line from the receiver (xr, yr) to (xs, ys) at the centre of `cell`
// (its projection on the line): where region_hider_along looks along the next line.
inline float region_fraction_at(int cell, int width, float xr, float yr, float xs, float ys) {
  const float dx = xs - xr, dy = ys - yr;
  const float cx = (float)(cell % width) + 0.5f - xr, cy = (float)(cell / width) + 0.5f - yr;
  return (cx * dx + cy * dy) / (dx * dx + dy * dy);
}

// The per-end tables (region_end_table) of `count` points toward the rectangle where their sight
// lines' other ends lie (`other`: x0, y0, x1, y1), REGION_END_RECORD floats each: the shared source
// samples (`placed`: x, y, z each in `points`, as region_visibility_bits takes them) or a pair's
// receiver samples (drawn from `table` here, as region_visibility_bits draws them).
__kernel void region_end_tables(__global const float* h, __global const float* pyramid, int levels,
                                float margin, float z_bound, RegionDeviceField f, int placed,
                                __global const float* points, __global const float* table, int absolute,
                                unsigned int seed, int count, float4 other, __global float* records) {
  const int s = (int)get_global_id(0);
  if (s >= count) return;
  float x, y, z;
  if (placed) {
    x = points[3 * s], y = points[3 * s + 1], z = points[3 * s + 2];
  } else {
    region_sample(table, h, f.width, f.height, absolute, region_table_seed(table, seed), 0U, s, &x, &y, &z);
  }
  // (written in place, band by band: region_end_table keeps 3 * REGION_END_WEDGES floats of its own)
  region_end_table(pyramid, levels, f.width, f.height, margin, f.curvature, f.cell_x, f.cell_y, x, y, z,
                   z_bound, other.x, other.y, other.z, other.w, records + (size_t)s * REGION_END_RECORD);
}

__kernel void region_visibility_bits(__global const float* h, __global const float* pyramid, int levels,
                                     float margin, float gradient, int finite_field, int certify_receivers,
                                     int certify_sources, __global const float* receiver_records,
                                     __global const float* source_records, RegionDeviceField f,
                                     __global const float* sources, __global const float* source_points,
                                     int source_absolute, int samples, int pixel_receivers,
                                     __global const float* receivers, int receiver_absolute,
                                     int receiver_count, float target_height, unsigned int seed,
                                     int decorrelate, int words, int receiver_major, int first,
                                     __global unsigned int* bits) {
  const int r = first + (int)get_global_id(0);
  if (r >= receiver_count) return;
  float xr, yr, zr;
  if (!pixel_receivers) {
    region_sample(receivers, h, f.width, f.height, receiver_absolute, region_table_seed(receivers, seed), 0U,
                  r, &xr, &yr, &zr);
  } else {
    xr = (float)(r % f.width);
    yr = (float)(r / f.width);
    zr = h[r] + target_height;
  }
  const unsigned int key = decorrelate ? (unsigned int)r + 1U : 0U;
  const unsigned int source_seed = decorrelate ? region_table_seed(sources, seed) : 0U;
  // Culled: the cell that hid the last hidden sight line (and its fraction of that line from the
  // receiver), tried first against the next ones, across words, while the line before was hidden
  // (after a clear one the next is seldom hidden: the tries would cost more than they save); then
  // the two cells that hid lines before it, the more recent first (on a city the lines of one
  // receiver go behind a few walls in turn, so a wall met before often hides the next line again:
  // 13 - 22 % less CPU time on the city DSM's pairs, bench/report/region_visibility.md); a word
  // whose predecessor had a hidden line skips the shaft test (it fails where a line is hidden
  // beyond the receiver's surroundings, and then costs more than it saves).
  int blocker = -1, hidden_before = 0, last_hidden = 0;
  int earlier[2] = {-1, -1};  // the hiding cells before `blocker`, the more recent first
  float along = 0.0f;
  for (int w = 0; w < words; ++w) {
    unsigned int word = 0U;
    int hidden = 0;
    if (!isnan(zr)) {
      const int end = 32 * w + 32 < samples ? 32 * w + 32 : samples;
      float xs[32], ys[32], zs[32];
      for (int s = 32 * w; s < end; ++s)
        if (decorrelate) {
          region_sample(sources, h, f.width, f.height, source_absolute, source_seed, key, s, &xs[s - 32 * w],
                        &ys[s - 32 * w], &zs[s - 32 * w]);
        } else {
          xs[s - 32 * w] = source_points[3 * s], ys[s - 32 * w] = source_points[3 * s + 1];
          zs[s - 32 * w] = source_points[3 * s + 2];
        }
      // The marches confined to the receiver's surroundings where the shaft to the word's samples
      // is clear beyond them (else a box that holds nothing).
      float box[4] = {1.0f, 0.0f, 0.0f, 0.0f};
      if (levels > 0 && (hidden_before || !region_shaft_clear(h, pyramid, levels, margin, f, xr, yr, zr, xs,
                                                              ys, zs, end - 32 * w, box)))
        box[0] = 1.0f, box[2] = 0.0f;
      for (int i = 0; i < end - 32 * w; ++i) {
        if (blocker >= 0 && last_hidden) {
          if (region_cull_hides(h, f.width, f.height, f.cell_x, f.cell_y, f.curvature, f.max_d2, margin,
                                gradient, finite_field, blocker, xs[i], ys[i], zs[i], xr, yr, zr)) {
            hidden = 1, last_hidden = 1;
            continue;
          }
          const int next = region_hider_along(h, f, margin, gradient, finite_field, along, blocker, xr, yr,
                                              zr, xs[i], ys[i], zs[i]);
          if (next >= 0) {
            blocker = next, hidden = 1, last_hidden = 1;
            continue;
          }
          const int found =
              earlier[0] >= 0 && region_cull_hides(h, f.width, f.height, f.cell_x, f.cell_y, f.curvature,
                                                   f.max_d2, margin, gradient, finite_field, earlier[0],
                                                   xs[i], ys[i], zs[i], xr, yr, zr)
                  ? 0
              : earlier[1] >= 0 && region_cull_hides(h, f.width, f.height, f.cell_x, f.cell_y, f.curvature,
                                                     f.max_d2, margin, gradient, finite_field, earlier[1],
                                                     xs[i], ys[i], zs[i], xr, yr, zr)
                  ? 1
                  : -1;
          if (found >= 0) {  // it becomes `blocker`
            const int cell = earlier[found];
            if (found == 1) earlier[1] = earlier[0];
            earlier[0] = blocker;
            blocker = cell, hidden = 1, last_hidden = 1;
            along = region_fraction_at(cell, f.width, xr, yr, xs[i], ys[i]);
            continue;
          }
        }
        // The stretches from both ends that their tables certify clear (the march skips them); tried
        // after a clear line (after a hidden one the next is seldom clear: the look-ups would cost
        // more than they save).
        float reach_s = 0.0f, reach_r = 0.0f;
        if (!last_hidden && (certify_receivers || certify_sources)) {
          const float dx = xr - xs[i], dy = yr - ys[i], length = sqrt(dx * dx + dy * dy);
          if (certify_receivers && length > 0.0f) {
            __global const float* rec = receiver_records + (size_t)r * REGION_END_RECORD;
            const int wedge = region_end_wedge(rec[0], rec[1], -dx, -dy);
            if (wedge >= 0)
              reach_r =
                  region_end_reach(rec + 4 + 2 * wedge * REGION_END_BANDS, (int)rec[2], length, zr, zs[i]);
          }
          if (certify_sources && length > 0.0f && reach_r < length) {
            __global const float* rec = source_records + (size_t)(32 * w + i) * REGION_END_RECORD;
            const int wedge = region_end_wedge(rec[0], rec[1], dx, dy);
            if (wedge >= 0)
              reach_s =
                  region_end_reach(rec + 4 + 2 * wedge * REGION_END_BANDS, (int)rec[2], length, zs[i], zr);
          }
        }
        int blocked_at = -1;
        if (region_sight_visible_culled(h, f.width, f.height, f.cell_x, f.cell_y, f.curvature, f.max_d2,
                                        pyramid, levels, margin, box[0], box[1], box[2], box[3], xs[i], ys[i],
                                        zs[i], xr, yr, zr, reach_s, reach_r, &blocked_at)) {
          word |= 1U << i;
          last_hidden = 0;
        } else {
          hidden = 1, last_hidden = 1;
          if (levels > 0 && blocked_at >= 0) {
            if (blocker >= 0 && blocker != blocked_at) earlier[1] = earlier[0], earlier[0] = blocker;
            blocker = blocked_at;
            along = region_fraction_at(blocked_at, f.width, xr, yr, xs[i], ys[i]);
          }
        }
      }
    }
    hidden_before = hidden;
    bits[receiver_major ? (size_t)r * words + w : (size_t)w * receiver_count + r] = word;
  }
}

// ---------------------------------------------------------------------------------------------
// The bitmask method (RegionVisibilityMethod::Bitmask): the scatter of Eisemann & Décoret
// (2007, "Visibility sampling on GPU and applications") for a planar light at height `light_z`
// over every-pixel receivers. Per receiver, each cell that may reach the shaft to the light is
// back-projected from the receiver onto the light's plane and the samples inside come from a
// table of edge bitmasks (`table`: per edge angle and offset, the samples on the edge's inner
// side), ANDed per edge and ORed over the cells. The bilinear cell's back-projection has curved
// edges, so each cell gives a conservative pair: an outer polygon (the box under the cell's
// highest corner, raised by the march's rounding) that holds every sample the cell may hide, and
// an inner one (the box under its lowest corner, lowered by the march's rounding and the most
// its values can stray) whose samples it surely hides; each table edge rounded outward or
// inward by its resolution. The receiver's own four cells, whose back-projections reach to the
// horizon, are decided per sample from their bilinear surface along the line. Samples in some
// outer polygon but in no inner one are uncertain: the culled march (its bits the exact
// method's) decides them, so the bits are the exact method's, bit for bit.

// The table's shape: `angles` edge normals n_i = (cos, sin)(2 pi i / angles), `offsets` + 1
// offsets c_j = -rho + 2 rho j / offsets, a mask of `words` words per (i, j): the samples p with
// n_i . (p - centre) >= c_j.
typedef struct {
  float centre_x, centre_y, rho;
  int angles, offsets;
} BitmaskTable;

// ORs into acc the samples inside the convex hull of the n points (px, py) on the light's plane,
// as the table gives them: `outward`, a superset (each edge moved out by the table's resolution
// and `error`, the points' rounding, per unit of their magnitude); else a subset (moved in). An
// outer polygon may drop an edge (a larger polygon), an inner one may not (then it is empty).
void region_bitmask_polygon(float* px, float* py, int n, __global const unsigned int* table, BitmaskTable t,
                            int words, int outward, float error, unsigned int* acc) {
  // Andrew's monotone chain: sorted by x then y, the lower and upper hulls, counter-clockwise.
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && (px[j] < px[j - 1] || (px[j] == px[j - 1] && py[j] < py[j - 1])); --j) {
      const float sx = px[j], sy = py[j];
      px[j] = px[j - 1], py[j] = py[j - 1], px[j - 1] = sx, py[j - 1] = sy;
    }
  float hx[17], hy[17];
  int m = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const int floor_m = m;
    for (int k = 0; k < n; ++k) {
      const int i = pass ? n - 1 - k : k;
      while (m >= floor_m + 2 &&
             (hx[m - 1] - hx[m - 2]) * (py[i] - hy[m - 2]) - (hy[m - 1] - hy[m - 2]) * (px[i] - hx[m - 2]) <=
                 0.0f)
        --m;
      hx[m] = px[i], hy[m] = py[i], ++m;
    }
    --m;  // each chain's last point starts the other
  }
  if (m < 3) {
    if (!outward) return;  // a degenerate inner polygon: nothing surely hidden
  }
  // The magnitude the points' rounding scales with.
  float magnitude = t.rho + fabs(t.centre_x) + fabs(t.centre_y);
  for (int k = 0; k < m; ++k) magnitude = fmax(magnitude, fabs(hx[k]) + fabs(hy[k]));
  const float step = 2.0f * t.rho / (float)t.offsets, half_angle = M_PI_F / (float)t.angles;
  int column[16], edges = 0;
  for (int k = 0; k < m; ++k) {
    const float ax = hx[k], ay = hy[k], bx = hx[k + 1 < m ? k + 1 : 0], by = hy[k + 1 < m ? k + 1 : 0];
    const float ex = bx - ax, ey = by - ay, len = sqrt(ex * ex + ey * ey);
    // The inner normal of a counter-clockwise edge, and the edge's offset from the table's centre.
    const float nx = -ey / len, ny = ex / len;
    const float c = nx * (ax - t.centre_x) + ny * (ay - t.centre_y);
    // The edge's rounding where it passes the samples (its direction from the points' rounding
    // over its length), and the table's: the nearest angle's normal differs by at most half an
    // angle step, times the samples' distance from the centre.
    const float reach =
        sqrt((ax - t.centre_x) * (ax - t.centre_x) + (ay - t.centre_y) * (ay - t.centre_y)) + t.rho;
    const float slack = error * magnitude * (2.0f + reach / len) + t.rho * (half_angle + 1e-5f);
    if (!(len > 1e-6f * magnitude) || !isfinite(slack)) {
      if (!outward) return;
      continue;
    }
    int i = (int)floor(atan2(ny, nx) / (2.0f * half_angle) + 0.5f);
    i = ((i % t.angles) + t.angles) % t.angles;
    const float at = (outward ? c - slack : c + slack) + t.rho;  // from c_0
    if (outward) {
      if (at < 0.0f) continue;        // every sample on the inner side
      if (at > 2.0f * t.rho) return;  // none
      column[edges++] = i * (t.offsets + 1) + min((int)floor(at / step), t.offsets);
    } else {
      if (at <= 0.0f) continue;
      const int j = (int)ceil(at / step);
      if (j > t.offsets) return;
      column[edges++] = i * (t.offsets + 1) + j;
    }
  }
  for (int w = 0; w < words; ++w) {
    unsigned int mask = 0xffffffffU;
    for (int e = 0; e < edges; ++e) mask &= table[(size_t)column[e] * words + w];
    acc[w] |= mask;
  }
}

// ORs into acc the table's samples inside the back-projection from the receiver (xr, yr, zr)
// onto the plane z = light_z of the prism under the triangle (vx, vy, vz) (3 vertices; a plane)
// and above z = low (zr < low): the part of the triangle where the plane lies above `low`, and
// the volume between; a convex polytope, its projection the convex hull of its vertices'.
void region_bitmask_prism(const float* vx, const float* vy, const float* vz, float low, float xr, float yr,
                          float zr, float light_z, __global const unsigned int* table, BitmaskTable t,
                          int words, int outward, unsigned int* acc) {
  // The triangle clipped to plane >= low (Sutherland-Hodgman, one plane): at most 4 vertices.
  float cx[4], cy[4], cz[4], top = low;
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const int j = i < 2 ? i + 1 : 0;
    const float di = vz[i] - low, dj = vz[j] - low;
    if (di >= 0.0f) cx[n] = vx[i], cy[n] = vy[i], cz[n] = vz[i], top = fmax(top, vz[i]), ++n;
    if ((di >= 0.0f) != (dj >= 0.0f)) {
      const float f = di / (di - dj);
      cx[n] = vx[i] + f * (vx[j] - vx[i]), cy[n] = vy[i] + f * (vy[j] - vy[i]), cz[n] = low, ++n;
    }
  }
  if (n == 0) return;
  const float k0 = (light_z - zr) / (low - zr);
  if (!(low > zr) || !isfinite(k0)) {  // (low rounded onto zr): no polygon to trust
    for (int w = 0; outward && w < words; ++w) acc[w] = 0xffffffffU;
    return;
  }
  float px[8], py[8];
  for (int c = 0; c < n; ++c) {
    const float k = (light_z - zr) / (cz[c] - zr);
    px[c] = xr + (cx[c] - xr) * k0, py[c] = yr + (cy[c] - yr) * k0;
    px[n + c] = xr + (cx[c] - xr) * k, py[n + c] = yr + (cy[c] - yr) * k;
  }
  // The projection's rounding, relative: the divisions' and the heights' over low - zr.
  const float error = 2e-6f * (4.0f + (fabs(light_z) + fabs(top) + 2.0f * fabs(zr)) / (low - zr));
  region_bitmask_polygon(px, py, 2 * n, table, t, words, outward, error, acc);
}

// ORs into acc the back-projections of the prisms under the cell (x0, y0)'s triangulation along
// its diagonal from corner 00 to 11 (`main`) or from 10 to 01, each corner's height h raised by
// `raise` (negative: lowered), above `low`. The bilinear surface lies between the two
// triangulations: below the one along 00-11 where its twist h00 - h10 - h01 + h11 is positive,
// above it where negative. With `cull_front`, a triangle whose plane the receiver lies above is
// left out: over a surface without holes whose every point lies below the light, a line that
// passes under it leaves it upward through a triangle whose plane the receiver lies below (the
// line's rise over the surface grows there), and passes under that triangle just before
// (Eisemann & Décoret's front-face culling of a closed occluder).
void region_bitmask_cell(float x0, float y0, float h00, float h10, float h01, float h11, float raise,
                         int main, int cull_front, float low, float xr, float yr, float zr, float light_z,
                         __global const unsigned int* table, BitmaskTable t, int words, int outward,
                         unsigned int* acc) {
  const float x1 = x0 + 1.0f, y1 = y0 + 1.0f;
  const float a = h00 + raise, b = h10 + raise, c = h01 + raise, d = h11 + raise;
  // The two triangles, counter-clockwise from a corner on the diagonal's end.
  const float vx[2][3] = {{x0, x1, main ? x1 : x0}, {main ? x0 : x1, x1, x0}};
  const float vy[2][3] = {{y0, y0, main ? y1 : y1}, {main ? y0 : y0, y1, y1}};
  const float vz[2][3] = {{a, b, main ? d : c}, {main ? a : b, d, c}};
  for (int k = 0; k < 2; ++k) {
    if (cull_front) {
      // The triangle's plane at the receiver.
      const float ex1 = vx[k][1] - vx[k][0], ey1 = vy[k][1] - vy[k][0], ez1 = vz[k][1] - vz[k][0];
      const float ex2 = vx[k][2] - vx[k][0], ey2 = vy[k][2] - vy[k][0], ez2 = vz[k][2] - vz[k][0];
      const float det = ex1 * ey2 - ey1 * ex2;
      const float gx = (ez1 * ey2 - ey1 * ez2) / det, gy = (ex1 * ez2 - ez1 * ex2) / det;
      const float rx = xr - vx[k][0], ry = yr - vy[k][0];
      const float plane = vz[k][0] + gx * rx + gy * ry;
      if (zr > plane + 1e-5f * (fabs(zr) + fabs(vz[k][0]) + (fabs(gx) + fabs(gy)) * (fabs(rx) + fabs(ry))))
        continue;
    }
    region_bitmask_prism(vx[k], vy[k], vz[k], low, xr, yr, zr, light_z, table, t, words, outward, acc);
  }
}

// The bilinear cell between the receiver's grid point (xr, yr) (its corner h00) and the corners
// one step toward the sample along each axis, along the line to a sample (gx, gy) pixels away
// whose rise over the receiver's height is dz: the surface's rise over the line, f(l) = c0 +
// l A + l^2 B for the line's fraction l in [0, le] over the cell. *most: the most the march may
// find there (with the start's c0 <= 0 when the top lies at or a rounding before the start,
// which the march may take for inside); *surely: the most it takes inside the piece or at its
// end.
void region_bitmask_near(float h00, float h10, float h01, float h11, float zr, float ax, float ay, float dz,
                         float* most, float* surely) {
  const float a = h10 - h00, b = h01 - h00, tw = h00 - h10 - h01 + h11;
  const float le = fmin(1.0f, fmin(ax > 0.0f ? 1.0f / ax : INFINITY, ay > 0.0f ? 1.0f / ay : INFINITY));
  const float c0 = h00 - zr, A = a * ax + b * ay - dz, B = tw * ax * ay;
  const float fe = c0 + le * (A + le * B);
  *most = fe, *surely = fe;
  if (B < 0.0f) {
    const float top = -A / (2.0f * B);
    if (top > 0.0f && top < le) {
      const float ft = c0 + top * (A + top * B);
      *most = fmax(*most, ft), *surely = fmax(*surely, ft);
    }
    if (top > -1e-4f * le * (1.0f + fabs(fe - c0) / (-B * le * le))) *most = fmax(*most, c0);
  }
}

// Whether a | b holds every one of the samples.
int region_bitmask_all(const unsigned int* a, const unsigned int* b, int samples) {
  for (int w = 0; 32 * w < samples; ++w) {
    const int n = samples - 32 * w;
    const unsigned int valid = n >= 32 ? 0xffffffffU : (1U << n) - 1U;
    if ((a[w] | b[w]) != valid) return 0;
  }
  return 1;
}

__kernel void region_bitmask_bits(__global const float* h, __global const float* pyramid, int levels,
                                  float margin, float gradient, int finite_field, float field_top,
                                  RegionDeviceField f, __global const float* source_points, int samples,
                                  float light_z, float target_height, __global const unsigned int* table,
                                  BitmaskTable t, float lo_x, float lo_y, float hi_x, float hi_y, int words,
                                  int receiver_count, int receiver_major, int first,
                                  __global unsigned int* bits, __global unsigned int* tested) {
  const int r = first + (int)get_global_id(0);
  if (r >= receiver_count) return;
  const int xi = r % f.width, yi = r / f.width;
  const float xr = (float)xi, yr = (float)yi, zr = h[r] + target_height;
  unsigned int outer[32], inner[32], near_open[32], near_hidden[32];
  for (int w = 0; w < words; ++w) outer[w] = inner[w] = near_open[w] = near_hidden[w] = 0U;
  const float Z = light_z, dz = Z - zr;
  // The march's rounding (region_sight_visible_culled's clearance, doubled) and the rounding it
  // forgives: a cell whose highest corner lies this far below a line cannot hide it, and one that
  // rises this far above it (and more, in_margin) surely does.
  const float out_margin = 2.0f * margin + 4e-5f * (fabs(zr) + fabs(Z)) + region_forgiven(zr, Z, 0.0f);
  // The positions' rounding the march forgives at a crossing (region_position_reach, times the
  // surface's slope there, at most `gradient`): added to the margins by which a cell surely hides.
  const float reach =
      region_position_reach(xr, yr, fmax(fabs(lo_x), fabs(hi_x)), fmax(fabs(lo_y), fabs(hi_y)));
  // A light plane not above the receiver: every sample left to the march.
  int all_uncertain = !(dz > 0.0f);
  if (!isnan(zr) && !all_uncertain) {
    // The receiver's own cells, per sample: the line's rise over their bilinear surface.
    for (int s = 0; s < samples; ++s) {
      const float gx = source_points[3 * s] - xr, gy = source_points[3 * s + 1] - yr;
      if (gx == 0.0f && gy == 0.0f) continue;  // a vertical line sees
      const float ax = fabs(gx), ay = fabs(gy);
      const float pixels = fmax(ax, ay);
      const float in_margin = out_margin + 1.5e-3f * (1.5f * gradient + dz / pixels);
      int open = 0, hidden = 0;
      // The cell toward the sample along each axis (both on a line along the axis).
      for (int sx = gx > 0.0f ? 1 : -1; sx <= (gx < 0.0f ? -1 : 1); sx += 2)
        for (int sy = gy > 0.0f ? 1 : -1; sy <= (gy < 0.0f ? -1 : 1); sy += 2) {
          if (xi + sx < 0 || xi + sx >= f.width || yi + sy < 0 || yi + sy >= f.height) continue;
          const float h10 = h[r + sx], h01 = h[r + sy * f.width], h11 = h[r + sx + sy * f.width];
          if (!isfinite(h10) || !isfinite(h01) || !isfinite(h11)) {
            open = 1;
            continue;
          }
          float most, surely;
          region_bitmask_near(h[r], h10, h01, h11, zr, ax, ay, dz, &most, &surely);
          open = open || most > -out_margin;
          hidden = hidden || surely > in_margin + reach * gradient;
        }
      if (hidden)
        near_hidden[s / 32] |= 1U << (s % 32);
      else if (open)
        near_open[s / 32] |= 1U << (s % 32);
    }
    // The farther cells: the pyramid's blocks over the footprint (the box around the receiver
    // and the light), each left out when its highest point lies below the lowest any line can
    // be over it (the receiver's height plus the shallowest slope to the light times the
    // block's distance), by the march's rounding.
    float dmax = 0.0f, pmin = 0.0f;
    for (int c = 0; c < 4; ++c) {
      const float gx = ((c & 1) ? hi_x : lo_x) - xr, gy = ((c & 2) ? hi_y : lo_y) - yr;
      dmax = fmax(dmax, sqrt(gx * f.cell_x * gx * f.cell_x + gy * f.cell_y * gy * f.cell_y));
    }
    pmin = fmax(fmax(lo_x - xr, xr - hi_x), fmax(lo_y - yr, yr - hi_y));
    const float in_margin = pmin > 0.0f ? out_margin + 1.5e-3f * (1.5f * gradient + dz / pmin) : INFINITY;
    const float slope = dz / dmax;
    // Front faces culled only under a light above every point of the surfaces (the field's
    // highest plus the rounding).
    const int light_above = Z > field_top + 2.0f * out_margin;
    RegionBlockWalk walk;
    region_walk_init(&walk, xr, yr, lo_x, lo_y, hi_x, hi_y);
    // (no pyramid: no cells, a field one point thick; none where the receiver's own cells hide
    // every sample)
    const int visit = levels > 0 && !region_bitmask_all(near_hidden, near_hidden, samples);
    if (visit && !all_uncertain && !region_walk_start(&walk, levels, f.width, f.height)) all_uncertain = 1;
    int k, bx, by;
    float x0, y0, near, highest;
    while (!all_uncertain &&
           region_walk_next(&walk, pyramid, f, 0, &k, &bx, &by, &x0, &y0, &near, &highest)) {
      if (highest + out_margin < zr + slope * near) continue;
      if (k > 0) {
        if (!region_walk_descend(&walk, f, k, bx, by)) all_uncertain = 1;
        continue;
      }
      if (bx >= xi - 1 && bx <= xi && by >= yi - 1 && by <= yi) continue;  // the receiver's own
      if (isinf(highest)) {
        all_uncertain = 1;  // an infinite height on or beside the cell: no bound
        break;
      }
      // The boxes from the lowest height a line to the light can have over the cell (below it,
      // a point projects beyond the light's farthest corner), a little lower.
      const float low = zr + dz * (near / dmax) * 0.999f;
      const int p = by * f.width + bx;
      const float h00 = h[p], h10 = h[p + 1], h01 = h[p + f.width], h11 = h[p + f.width + 1];
      int finite = isfinite(h00) && isfinite(h10) && isfinite(h01) && isfinite(h11);
      const float twist = h00 - h10 - h01 + h11;
      // The 4 x 4 heights around the cell finite: the march's values near it are numbers (as
      // region_cull_hides), and the surfaces below are without holes there.
      int around = finite;
      for (int y = (by > 0 ? by - 1 : 0);
           around && !finite_field && y <= (by + 2 < f.height ? by + 2 : f.height - 1); ++y)
        for (int x = (bx > 0 ? bx - 1 : 0); x <= (bx + 2 < f.width ? bx + 2 : f.width - 1); ++x)
          around = around && isfinite(h[y * f.width + x]);
      const int cull_front = around && light_above;
      // Outer: the triangulation above the bilinear surface, raised by the march's rounding; a
      // cell with a nodata corner (only its valid edges are surface), the box under its highest.
      if (highest + out_margin > low) {
        if (finite)
          region_bitmask_cell(x0, y0, h00, h10, h01, h11, out_margin, twist >= 0.0f, cull_front, low, xr, yr,
                              zr, Z, table, t, words, 1, outer);
        else
          region_bitmask_cell(x0, y0, highest, highest, highest, highest, out_margin, 1, 0, low, xr, yr, zr,
                              Z, table, t, words, 1, outer);
      }
      // Inner: the triangulation below it, lowered by the march's rounding and the most its
      // values change over a piece it skips; only below the light (above it, the prism's points
      // lie beyond the line's end), where the march's values near the cell are numbers.
      const float cell_margin = in_margin + reach * gradient;
      if (around && highest - cell_margin <= Z && highest - cell_margin > low) {
        region_bitmask_cell(x0, y0, h00, h10, h01, h11, -cell_margin, twist < 0.0f, cull_front, low, xr, yr,
                            zr, Z, table, t, words, 0, inner);
        if (region_bitmask_all(inner, near_hidden, samples)) break;  // nothing left to decide
      }
    }
  }
  unsigned int uncertain_count = 0U, uncertain_visible = 0U;
  for (int w = 0; w < words; ++w) {
    const int end = 32 * w + 32 < samples ? 32 * w + 32 : samples;
    const unsigned int valid = end - 32 * w == 32 ? 0xffffffffU : (1U << (end - 32 * w)) - 1U;
    unsigned int word = 0U;
    if (!isnan(zr)) {
      const unsigned int hidden = inner[w] | near_hidden[w];
      const unsigned int uncertain = all_uncertain ? valid : (outer[w] | near_open[w]) & ~hidden & valid;
      word = all_uncertain ? 0U : ~(outer[w] | near_open[w] | hidden) & valid;
      for (int i = 0; i < end - 32 * w; ++i) {
        const int s = 32 * w + i;
        const float xs = source_points[3 * s], ys = source_points[3 * s + 1], zs = source_points[3 * s + 2];
        if (f.max_d2 > 0.0f) {  // out of reach: the march's own distance, whichever end first
          const float gx = fabs(xs - xr) * f.cell_x, gy = (ys - yr) * f.cell_y;
          if (gx * gx + gy * gy > f.max_d2) {
            word &= ~(1U << i);
            continue;
          }
        }
        if (!((uncertain >> i) & 1U)) continue;
        int blocked_at = -1;
        ++uncertain_count;
        if (region_sight_visible_culled(h, f.width, f.height, f.cell_x, f.cell_y, f.curvature, f.max_d2,
                                        pyramid, levels, margin, 1.0f, 0.0f, 0.0f, 0.0f, xs, ys, zs, xr, yr,
                                        zr, 0.0f, 0.0f, &blocked_at))
          word |= 1U << i, ++uncertain_visible;
      }
    }
    bits[receiver_major ? (size_t)r * words + w : (size_t)w * receiver_count + r] = word;
  }
  tested[2 * (size_t)r] = uncertain_count;
  tested[2 * (size_t)r + 1] = uncertain_visible;
}
