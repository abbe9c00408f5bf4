// sweep_framework.cl: what every sweep kernel shares: the ray geometry of the naive
// marches, bilinear height sampling with the nodata policy, and the per-period samples of
// the lattice lines that the horizon and hull-tree sweeps run on.
//
// Pixel axes: x = column, y = row; pixel (c, r) at (c, r). The lattice sweeps' scratch
// (hull stacks, tree nodes) is laid out by the host (src/core/lattice_geometry.hpp, chunkLines):
// line-major for CPUs, whose work-item runs one line serially, step-major for GPUs, whose
// neighbouring work-items then touch neighbouring entries; the kernels see only each line's
// first entry and the stride between its entries.
//
// Compile-time parameters (prepended #defines; every kernel compiles with the defaults):
//   HFVIS_HAS_NODATA  the field holds NaN heights: a bilinear sample with a nodata corner of
//                     positive weight is absent (0 = the faster path without checks)
//   HFVIS_EDGE_EPS    how far outside [0, W-1] x [0, H-1] (pixels) a sample still counts as
//                     inside (absorbs rounding of directions that are exactly axis-aligned)
#ifndef HFVIS_SWEEP_FRAMEWORK_CL
#define HFVIS_SWEEP_FRAMEWORK_CL

// Rounding must be identical in the scalar C++ references (built with -ffp-contract=off).
#pragma OPENCL FP_CONTRACT OFF

// Helpers must inline: PoCL vectorises across work-items only through straight-line code,
// and it does not inline calls of this size by itself.
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline __attribute__((always_inline))
#endif

#ifndef HFVIS_HAS_NODATA
#define HFVIS_HAS_NODATA 1
#endif
#ifndef HFVIS_EDGE_EPS
#define HFVIS_EDGE_EPS 1e-3f
#endif

// One direction's ray geometry (the naive visibility march reads dir, step and ground
// lengths). Must match struct SweepDirection in src/core/sweep_geometry.hpp: sixteen 4-byte
// members, no padding.
typedef struct {
  float dir_x, dir_y;    // unit line direction in pixel axes
  float perp_x, perp_y;  // (-dir_y, dir_x)
  float line_spacing;    // pixels between lines (1 / lines_per_unit)
  float lines_per_unit;
  float step_length;  // pixels between samples (1 / samples_per_unit)
  float samples_per_unit;
  float ground_per_pixel;          // ground length of one pixel length along dir
  float cos_azimuth, sin_azimuth;  // the direction on the ground, for shading
  int line_first;
  int n_lines;
  int step_top;
  int n_steps;
  uint buffer_offset;  // first entry of this direction in the line buffer
} SweepDirection;

// A direction's geometry read field by field: an aggregate load from global memory is
// an instruction PoCL's vectoriser cannot widen, which would keep a whole kernel scalar.
HFVIS_INLINE SweepDirection load_direction(__global const SweepDirection* p) {
  SweepDirection d;
  d.dir_x = p->dir_x;
  d.dir_y = p->dir_y;
  d.perp_x = p->perp_x;
  d.perp_y = p->perp_y;
  d.line_spacing = p->line_spacing;
  d.lines_per_unit = p->lines_per_unit;
  d.step_length = p->step_length;
  d.samples_per_unit = p->samples_per_unit;
  d.ground_per_pixel = p->ground_per_pixel;
  d.cos_azimuth = p->cos_azimuth;
  d.sin_azimuth = p->sin_azimuth;
  d.line_first = p->line_first;
  d.n_lines = p->n_lines;
  d.step_top = p->step_top;
  d.n_steps = p->n_steps;
  d.buffer_offset = p->buffer_offset;
  return d;
}

// How far (pixels along the unit direction (dir_x, dir_y)) the longest ray of this
// work-group's pixel tile runs inside the field: the same for every work-item of the group,
// so loops bounded by it have a uniform trip count and PoCL runs the group's work-items as
// vector lanes. The exit distance separates into a column and a row term, so the worst case
// is a tile corner's. For the per-pixel marches, whose work-groups are pixel tiles.
HFVIS_INLINE float tile_reach(float dir_x, float dir_y, int width, int height) {
  const int c_lo = get_group_id(0) * get_local_size(0), r_lo = get_group_id(1) * get_local_size(1);
  const int c_hi = min(c_lo + (int)get_local_size(0), width) - 1;
  const int r_hi = min(r_lo + (int)get_local_size(1), height) - 1;
  const float far = (float)(width + height);
  const float reach_x = dir_x > 0.0f   ? ((float)(width - 1) - (float)c_lo) / dir_x
                        : dir_x < 0.0f ? (float)c_hi / -dir_x
                                       : far;
  const float reach_y = dir_y > 0.0f   ? ((float)(height - 1) - (float)r_lo) / dir_y
                        : dir_y < 0.0f ? (float)r_hi / -dir_y
                                       : far;
  const float reach = reach_x < reach_y ? reach_x : reach_y;  // no fmin: PoCL calls it in scalar code
  return reach < far ? reach : far;
}

HFVIS_INLINE int inside_field(float x, float y, int width, int height) {
  return x >= -HFVIS_EDGE_EPS && x <= (float)(width - 1) + HFVIS_EDGE_EPS && y >= -HFVIS_EDGE_EPS &&
         y <= (float)(height - 1) + HFVIS_EDGE_EPS;
}

// The bilinear surface from the weights of a cell's corners (w00 = 1 - the others), as the
// corner h00 plus the weighted differences from it: exact where the corners are equal, so a flat
// plateau far from 0 stays flat (the weighted sum of its heights rounds by units in the last
// place of the height, and a unit of 3e7 one pixel away is a horizon of 63 degrees).
// src/core/sweep_geometry.hpp's cornerBilinear is the same expression.
HFVIS_INLINE float corner_bilinear(float h00, float h10, float h01, float h11, float w10, float w01, float w11) {
  return h00 + (w10 * (h10 - h00) + w01 * (h01 - h00) + w11 * (h11 - h00));
}

// A sample beside nodata (corner_bilinear gave NaN): NaN where a corner of positive weight is
// nodata, since a cell with a nodata corner has no surface inside and an edge with a nodata end
// none along it (the viewshed's, region visibility's and the ray caster's rule: one surface for
// every operation); else the bilinear value over the corners of positive weight (on an edge or
// at a grid point beside a hole, whose other corners weigh 0), from the first of them, so that
// equal corners give their height exactly. (Renormalising over a partial cell's valid corners,
// as before, put surface inside it that the sweeps, sampling grid-line crossings and the peaks
// of whole cells, never saw: a diagonal line through a nodata corner missed a rise of 15 m.)
// Branch-free (masked sums add exact zeros), so it vectorises; NaN is told by x != x, not by
// isnan, which PoCL leaves as a call that stops the vectoriser: with isnan here and in the
// callers' test below, the naive marches ran 3 - 4x slower on any field holding nodata
// (docs/PERFORMANCE.md, "Nodata"). The kernels are built
// without finite-math options, so x != x stays the IEEE test on every device.
// src/core/sweep_geometry.hpp's bilinearBesideNodata is the same.
HFVIS_INLINE float bilinear_beside_nodata(float h00, float h10, float h01, float h11, float w00, float w10,
                                          float w01, float w11) {
  int p00 = w00 > 0.0f, p10 = w10 > 0.0f, p01 = w01 > 0.0f, p11 = w11 > 0.0f;
  int holed = (p00 & (h00 != h00)) | (p10 & (h10 != h10)) | (p01 & (h01 != h01)) | (p11 & (h11 != h11));
  // (not holed: every corner of positive weight is valid; the sum over them, from the first)
  float base = p00 ? h00 : (p10 ? h10 : (p01 ? h01 : h11));
  float sum = (p00 ? w00 * (h00 - base) : 0.0f) + (p10 ? w10 * (h10 - base) : 0.0f) +
              (p01 ? w01 * (h01 - base) : 0.0f) + (p11 ? w11 * (h11 - base) : 0.0f);
  float weight = (p00 ? w00 : 0.0f) + (p10 ? w10 : 0.0f) + (p01 ? w01 : 0.0f) + (p11 ? w11 : 0.0f);
  return !holed & (weight > 0.0f) ? base + sum / weight : NAN;
}

HFVIS_INLINE float sample_cell_at(__global const float* heights, int width, int height, int row0, int x0,
                                  int y0, float fx, float fy);

// Bilinear height at (px, py), clamped into the field; NaN where a corner of positive weight is
// nodata (bilinear_beside_nodata). `heights` holds the field's rows from row0 on (rows beside
// (px, py) among them).
HFVIS_INLINE float sample_height_rows(__global const float* heights, int width, int height, int row0, float px,
                                      float py) {
  // Plain comparisons instead of clamp/floor/min builtins, which PoCL leaves as calls that
  // stop vectorisation. After clamping x, y >= 0, so truncation is floor.
  float x = px < 0.0f ? 0.0f : (px > (float)(width - 1) ? (float)(width - 1) : px);
  float y = py < 0.0f ? 0.0f : (py > (float)(height - 1) ? (float)(height - 1) : py);
  int x0 = (int)x, y0 = (int)y;
  x0 = x0 > width - 2 ? (width > 1 ? width - 2 : 0) : x0;
  y0 = y0 > height - 2 ? (height > 1 ? height - 2 : 0) : y0;
  return sample_cell_at(heights, width, height, row0, x0, y0, x - (float)x0, y - (float)y0);
}

// The bilinear height in the cell of lower corner (x0, y0) (the far corner clamped to the field)
// at fractions (fx, fy) of it; NaN where a corner of positive weight is nodata.
HFVIS_INLINE float sample_cell_at(__global const float* heights, int width, int height, int row0, int x0,
                                  int y0, float fx, float fy) {
  int x1 = x0 + 1 < width ? x0 + 1 : x0;
  int y1 = y0 + 1 < height ? y0 + 1 : y0;
  float h00 = heights[(y0 - row0) * width + x0];
  float h10 = heights[(y0 - row0) * width + x1];
  float h01 = heights[(y1 - row0) * width + x0];
  float h11 = heights[(y1 - row0) * width + x1];
  float w00 = (1.0f - fx) * (1.0f - fy);
  float w10 = fx * (1.0f - fy);
  float w01 = (1.0f - fx) * fy;
  float w11 = fx * fy;
  float plain = corner_bilinear(h00, h10, h01, h11, w10, w01, w11);
#if HFVIS_HAS_NODATA
  return plain != plain ? bilinear_beside_nodata(h00, h10, h01, h11, w00, w10, w01, w11) : plain;
#else
  return plain;
#endif
}

HFVIS_INLINE float sample_height(__global const float* heights, int width, int height, float px, float py) {
  return sample_height_rows(heights, width, height, 0, px, py);
}

// sample_height at (c + ox, r + oy), the fractions in the cell taken from the offsets, (c - x0) +
// ox, exact where |ox| >= 2 (Sterbenz) and within a unit in the last place of 1 below: the absolute
// position c + ox rounds by units in the last place of the column, which times a steep slope
// passed the visibility tie rule's rounding where a plane crosses 0 far from the field's corner
// (the naive visible count fell from 300 to 3 on h = 2 (column - 50), a probe's find). The cell is
// the absolute position's (a fraction a rounding below 0 or above 1 extends the cell's surface).
// src/core/sweep_geometry.hpp's sampleHeightFrom is the same.
HFVIS_INLINE float sample_height_from(__global const float* heights, int width, int height, int c, int r,
                                      float ox, float oy) {
  const float px = (float)c + ox, py = (float)r + oy;
  const float x = px < 0.0f ? 0.0f : (px > (float)(width - 1) ? (float)(width - 1) : px);
  const float y = py < 0.0f ? 0.0f : (py > (float)(height - 1) ? (float)(height - 1) : py);
  int x0 = (int)x, y0 = (int)y;
  x0 = x0 > width - 2 ? (width > 1 ? width - 2 : 0) : x0;
  y0 = y0 > height - 2 ? (height > 1 ? height - 2 : 0) : y0;
  const float fx = x == px ? (float)(c - x0) + ox : x - (float)x0;  // (clamped: as sample_height)
  const float fy = y == py ? (float)(r - y0) + oy : y - (float)y0;
  return sample_cell_at(heights, width, height, 0, x0, y0, fx, fy);
}

// One sample of a period (src/core/lattice_geometry.hpp, struct LatticeSample): nine 4-byte
// members, read field by field.
typedef struct {
  float tau;                 // pixels from the period's receiver toward +(a, b)
  int ox, oy;                // the cell's lower corner, relative to the receiver
  int ex, ey;                // 1 where the sample is strictly inside the cell along x (y)
  float w00, w10, w01, w11;  // bilinear weights of the cell's corners
} LatticeSample;

// Height of the bilinear surface at a lattice sample whose cell corner is at entry `at`; NaN
// where a corner of positive weight is nodata (bilinear_beside_nodata). Crossing samples have ex
// or ey 0: their zero-weight corners repeat a used one.
HFVIS_INLINE float lattice_height(__global const float* heights, uint at, uint right, uint down, float w00,
                                  float w10, float w01, float w11) {
  float h00 = heights[at], h10 = heights[at + right], h01 = heights[at + down],
        h11 = heights[at + down + right];
  float plain = corner_bilinear(h00, h10, h01, h11, w10, w01, w11);
#if HFVIS_HAS_NODATA
  return plain != plain ? bilinear_beside_nodata(h00, h10, h01, h11, w00, w10, w01, w11) : plain;
#else
  return plain;
#endif
}

#endif  // HFVIS_SWEEP_FRAMEWORK_CL
