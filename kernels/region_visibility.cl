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
} RegionField;

// The cells around the receiver's point, each side, that its sight lines march exactly when the
// shaft to a word's samples is shown clear beyond them (region_shaft_clear).
#define REGION_NEAR_CELLS 2

// Whether every segment from the receiver (xr, yr, zr) to the n samples (xs, ys, zs) is clear of
// the surface outside the box of grid lines around the receiver (REGION_NEAR_CELLS cells each
// side of its point, *box: x0, y0, x1, y1), by the margins of the culled march: every block of
// the pyramid over the shaft's footprint (the wedge from the receiver to the samples' bounding
// box) lies below the lowest the shaft can be over it (the receiver's height plus the smallest
// slope to a sample times the block's ground distance) by the march's clearance. Blocks within
// the box are left to the segments' own marches; 0 when a cell outside it may reach the shaft.
int region_shaft_clear(__global const float* h, __global const float* pyramid, int levels, float margin,
                       RegionField f, float xr, float yr, float zr, const float* xs, const float* ys,
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
  const float fx0 = fmin(xr, sx0), fx1 = fmax(xr, sx1), fy0 = fmin(yr, sy0), fy1 = fmax(yr, sy1);
  const int wedge = xr < sx0 || xr > sx1 || yr < sy0 || yr > sy1;
  float lx = 0.0f, ly = 0.0f, rxe = 0.0f, rye = 0.0f;
  if (wedge) {
    const float cx = 0.5f * (sx0 + sx1) - xr, cy = 0.5f * (sy0 + sy1) - yr;
    float most = -INFINITY, least = INFINITY;
    for (int c = 0; c < 4; ++c) {
      const float vx = (c & 1 ? sx1 : sx0) - xr, vy = (c & 2 ? sy1 : sy0) - yr;
      const float sine = (cx * vy - cy * vx) / sqrt(vx * vx + vy * vy);
      if (sine > most) most = sine, lx = vx, ly = vy;
      if (sine < least) least = sine, rxe = vx, rye = vy;
    }
  }
  int stack_k[64], stack_x[64], stack_y[64], top = 0;
  const int last = levels - 1;
  for (int by = 0; by < region_cull_width(f.height, last); ++by)
    for (int bx = 0; bx < region_cull_width(f.width, last); ++bx) {
      if (top == 64) return 0;
      stack_k[top] = last, stack_x[top] = bx, stack_y[top] = by, ++top;
    }
  while (top > 0) {
    --top;
    const int k = stack_k[top], bx = stack_x[top], by = stack_y[top];
    const float x0 = (float)(bx << k), y0 = (float)(by << k);
    const float x1 = fmin((float)((bx + 1) << k), (float)(f.width - 1)),
                y1 = fmin((float)((by + 1) << k), (float)(f.height - 1));
    if (x1 < fx0 || x0 > fx1 || y1 < fy0 || y0 > fy1) continue;
    if (x0 >= box[0] && x1 <= box[2] && y0 >= box[1] && y1 <= box[3]) continue;
    if (wedge) {
      int left = 0, right = 0;
      for (int c = 0; c < 4; ++c) {
        const float qx = (c & 1 ? x1 : x0) - xr, qy = (c & 2 ? y1 : y0) - yr;
        left += lx * qy - ly * qx > 0.0f;
        right += rxe * qy - rye * qx < 0.0f;
      }
      if (left == 4 || right == 4) continue;
    }
    const float ddx = fmax(0.0f, fmax(x0 - xr, xr - x1)) * f.cell_x,
                ddy = fmax(0.0f, fmax(y0 - yr, yr - y1)) * f.cell_y;
    const float near = sqrt(ddx * ddx + ddy * ddy);
    const float lowest = zr + slope * (slope >= 0.0f ? near : far);
    const float highest =
        pyramid[region_cull_offset(f.width, f.height, k) + by * region_cull_width(f.width, k) + bx];
    if (highest + clearance < lowest) continue;
    if (k == 0 || top + 4 > 64) return 0;
    for (int c = 0; c < 4; ++c) {
      const int cx = 2 * bx + (c & 1), cy = 2 * by + (c >> 1);
      if (cx < region_cull_width(f.width, k - 1) && cy < region_cull_width(f.height, k - 1))
        stack_k[top] = k - 1, stack_x[top] = cx, stack_y[top] = cy, ++top;
    }
  }
  return 1;
}

// The cell to try against the sight line from the receiver (xr, yr, zr) to (xs, ys, zs) when the
// cell that hid the last hidden line does not hide it: the cell at the same fraction `along` of
// the new line from the receiver as that one was of its line, or one cell before or after it,
// the first that region_cull_hides shows hiding it (lines to neighbouring samples cross a ridge
// at about the same fraction, in neighbouring cells); -1 when none does.
int region_hider_along(__global const float* h, RegionField f, float margin, float gradient, int finite_field,
                       float along, int tried, float xr, float yr, float zr, float xs, float ys, float zs) {
  const float dx = xs - xr, dy = ys - yr, pixels = fmax(fabs(dx), fabs(dy));
  if (!(pixels > 0.0f)) return -1;
  for (int k = -1; k <= 1; ++k) {
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

// The per-end tables (region_end_table) of `count` points toward the rectangle where their sight
// lines' other ends lie (`other`: x0, y0, x1, y1), REGION_END_RECORD floats each: the shared source
// samples (`placed`: x, y, z each in `points`, as region_visibility_bits takes them) or a pair's
// receiver samples (drawn from `table` here, as region_visibility_bits draws them).
__kernel void region_end_tables(__global const float* h, __global const float* pyramid, int levels,
                                float margin, float z_bound, RegionField f, int placed,
                                __global const float* points, __global const float* table, int absolute,
                                unsigned int seed, int count, float4 other, __global float* records) {
  const int s = (int)get_global_id(0);
  if (s >= count) return;
  float x, y, z;
  if (placed) {
    x = points[3 * s], y = points[3 * s + 1], z = points[3 * s + 2];
  } else {
    region_sample(table, h, f.width, f.height, absolute, seed, 0U, s, &x, &y, &z);
  }
  float rec[REGION_END_RECORD];
  region_end_table(pyramid, levels, f.width, f.height, margin, f.curvature, f.cell_x, f.cell_y, x, y, z,
                   z_bound, other.x, other.y, other.z, other.w, rec);
  for (int i = 0; i < REGION_END_RECORD; ++i) records[(size_t)s * REGION_END_RECORD + i] = rec[i];
}

__kernel void region_visibility_bits(__global const float* h, __global const float* pyramid, int levels,
                                     float margin, float gradient, int finite_field, int certify_receivers,
                                     int certify_sources, __global const float* receiver_records,
                                     __global const float* source_records, RegionField f,
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
    region_sample(receivers, h, f.width, f.height, receiver_absolute, seed, 0U, r, &xr, &yr, &zr);
  } else {
    xr = (float)(r % f.width);
    yr = (float)(r / f.width);
    zr = h[r] + target_height;
  }
  const unsigned int key = decorrelate ? (unsigned int)r + 1U : 0U;
  // Culled: the cell that hid the last hidden sight line (and its fraction of that line from the
  // receiver), tried first against the next ones, across words, while the line before was hidden
  // (after a clear one the next is seldom hidden: the tries would cost more than they save); a
  // word whose predecessor had a hidden line skips the shaft test (it fails where a line is hidden
  // beyond the receiver's surroundings, and then costs more than it saves).
  int blocker = -1, hidden_before = 0, last_hidden = 0;
  float along = 0.0f;
  for (int w = 0; w < words; ++w) {
    unsigned int word = 0U;
    int hidden = 0;
    if (!isnan(zr)) {
      const int end = 32 * w + 32 < samples ? 32 * w + 32 : samples;
      float xs[32], ys[32], zs[32];
      for (int s = 32 * w; s < end; ++s)
        if (decorrelate) {
          region_sample(sources, h, f.width, f.height, source_absolute, seed, key, s, &xs[s - 32 * w],
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
            // The fraction of the line from the receiver at the hiding cell's centre.
            const float dx = xs[i] - xr, dy = ys[i] - yr;
            const float cx = (float)(blocked_at % f.width) + 0.5f - xr,
                        cy = (float)(blocked_at / f.width) + 0.5f - yr;
            blocker = blocked_at;
            along = (cx * dx + cy * dy) / (dx * dx + dy * dy);
          }
        }
      }
    }
    hidden_before = hidden;
    bits[receiver_major ? (size_t)r * words + w : (size_t)w * receiver_count + r] = word;
  }
}
