// sweep_framework.cl: what every sweep kernel shares: the per-direction line geometry,
// bilinear height sampling with the nodata policy, and the line presampling pass.
//
// Geometry (pixel axes, x = column, y = row; pixel (c, r) at (c, r)): lines run along the
// unit direction `dir`; line j lies at perpendicular offset (line_first + j) * line_spacing
// along `perp`; step i of every line lies at t = (step_top - i) * step_length along `dir`,
// so step 0 is the far end and a line is swept toward -dir. All lines of a direction share
// the step lattice. Line buffers have one entry per (line, step); where it sits is the
// layout (HFVIS_LINE_MAJOR below), reached only through line_entry() and line_stride().
//
// Compile-time parameters (prepended #defines; every kernel compiles with the defaults):
//   HFVIS_HAS_NODATA  the field holds NaN heights: bilinear samples renormalise over the
//                     valid corners (0 = the faster path without checks)
//   HFVIS_EDGE_EPS    how far outside [0, W-1] x [0, H-1] (pixels) a sample still counts as
//                     inside (absorbs rounding of directions that are exactly axis-aligned)
//   HFVIS_LINE_MAJOR  0: entry (line j, step i) at i * n_lines + j, so work-items (lines)
//                     at the same step touch adjacent addresses: coalesced on GPUs.
//                     1: at j * n_steps + i, so one work-item walks its line contiguously:
//                     CPUs run a work-item's loop serially, and the step-major stride
//                     costs a cache line and often a TLB entry per step.
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
#ifndef HFVIS_LINE_MAJOR
#define HFVIS_LINE_MAJOR 0
#endif

// One direction's sweep geometry. Must match struct SweepDirection in
// src/sweep_geometry.hpp: sixteen 4-byte members, no padding.
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

// Index of entry (line, step) of direction d in a line-sized buffer, and the distance
// between consecutive steps of one line.
HFVIS_INLINE uint line_entry(const SweepDirection d, int line, int step) {
#if HFVIS_LINE_MAJOR
  return d.buffer_offset + (uint)line * (uint)d.n_steps + (uint)step;
#else
  return d.buffer_offset + (uint)step * (uint)d.n_lines + (uint)line;
#endif
}

HFVIS_INLINE uint line_stride(const SweepDirection d) {
#if HFVIS_LINE_MAJOR
  return 1u;
#else
  return (uint)d.n_lines;
#endif
}

// Position of step `step` of line `line` (pixel axes). Scalars, not float2: PoCL's
// vectoriser widens scalar code across work-items but not vector-typed values.
HFVIS_INLINE void sweep_position(const SweepDirection d, int line, int step, float* x, float* y) {
  float s = (float)(d.line_first + line) * d.line_spacing;
  float t = (float)(d.step_top - step) * d.step_length;
  *x = s * d.perp_x + t * d.dir_x;
  *y = s * d.perp_y + t * d.dir_y;
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

// Bilinear height at (px, py), clamped into the field. With nodata, only the valid corners
// count and their weights are renormalised; NaN when no corner with weight is valid.
// Branch-free (masked sums add exact zeros), so it vectorises.
HFVIS_INLINE float sample_height(__global const float* heights, int width, int height, float px, float py) {
  // Plain comparisons instead of clamp/floor/min builtins, which PoCL leaves as calls that
  // stop vectorisation. After clamping x, y >= 0, so truncation is floor.
  float x = px < 0.0f ? 0.0f : (px > (float)(width - 1) ? (float)(width - 1) : px);
  float y = py < 0.0f ? 0.0f : (py > (float)(height - 1) ? (float)(height - 1) : py);
  int x0 = (int)x, y0 = (int)y;
  x0 = x0 > width - 2 ? (width > 1 ? width - 2 : 0) : x0;
  y0 = y0 > height - 2 ? (height > 1 ? height - 2 : 0) : y0;
  int x1 = x0 + 1 < width ? x0 + 1 : x0;
  int y1 = y0 + 1 < height ? y0 + 1 : y0;
  float fx = x - (float)x0;
  float fy = y - (float)y0;
  float h00 = heights[y0 * width + x0];
  float h10 = heights[y0 * width + x1];
  float h01 = heights[y1 * width + x0];
  float h11 = heights[y1 * width + x1];
  float w00 = (1.0f - fx) * (1.0f - fy);
  float w10 = fx * (1.0f - fy);
  float w01 = (1.0f - fx) * fy;
  float w11 = fx * fy;
  float plain = w00 * h00 + w10 * h10 + w01 * h01 + w11 * h11;
#if HFVIS_HAS_NODATA
  int n00 = h00 != h00, n10 = h10 != h10, n01 = h01 != h01, n11 = h11 != h11;  // isnan
  float sum = 0.0f, weight = 0.0f;
  sum += n00 ? 0.0f : w00 * h00;
  weight += n00 ? 0.0f : w00;
  sum += n10 ? 0.0f : w10 * h10;
  weight += n10 ? 0.0f : w10;
  sum += n01 ? 0.0f : w01 * h01;
  weight += n01 ? 0.0f : w01;
  sum += n11 ? 0.0f : w11 * h11;
  weight += n11 ? 0.0f : w11;
  float renormalised = weight > 0.0f ? sum / weight : NAN;
  return (n00 || n10 || n01 || n11) ? renormalised : plain;
#else
  return plain;
#endif
}

// Where receiver pixel (x, y) falls among direction d's line samples: the cell of the
// four entries around it, corner k = 0..3 at (line j0 + (k & 1), step i0 + (k >> 1)), and
// its fractional position (fu, fv) in the cell. Every reduction interpolates this way.
HFVIS_INLINE void receiver_cell(const SweepDirection d, float x, float y, int* j0, int* i0, float* fu,
                                float* fv) {
  float t = x * d.dir_x + y * d.dir_y;
  float u = (x * d.perp_x + y * d.perp_y) * d.lines_per_unit - (float)d.line_first;
  float v = (float)d.step_top - t * d.samples_per_unit;
  *j0 = (int)floor(u);
  *i0 = (int)floor(v);
  *fu = u - (float)*j0;
  *fv = v - (float)*i0;
}

// Corner k of a receiver's cell: its bilinear weight (0 where it lies outside the line
// buffer), its step, and its entry index, clamped into the buffer so that reading it is
// always safe (branch-free, for the vectoriser).
HFVIS_INLINE uint cell_corner(const SweepDirection d, int j0, int i0, float fu, float fv, int k,
                              float* weight, int* step) {
  int j = j0 + (k & 1), i = i0 + (k >> 1);
  float w = ((k & 1) ? fu : 1.0f - fu) * ((k >> 1) ? fv : 1.0f - fv);
  int in_buffer = j >= 0 && j < d.n_lines && i >= 0 && i < d.n_steps;
  *weight = in_buffer ? w : 0.0f;
  *step = i;
  return line_entry(d, clamp(j, 0, d.n_lines - 1), clamp(i, 0, d.n_steps - 1));
}

// Presampling pass: the height at every (step, line) of the batch's directions, NaN where
// the sample lies outside the field or has no valid corner. Uniform control flow, so
// PoCL vectorises it across lines; the sweep then only reads one float per step.
// Global size: (max lines, max steps, directions in batch), or (max steps, max lines, ...)
// with HFVIS_LINE_MAJOR; any local size.
__kernel void presample_lines(__global const float* heights, int width, int height,
                              __global const SweepDirection* directions, __global float2* lines) {
#if HFVIS_LINE_MAJOR  // work-items adjacent along a line write adjacent entries
  int step = get_global_id(0), line = get_global_id(1);
#else
  int line = get_global_id(0), step = get_global_id(1);
#endif
  const SweepDirection d = load_direction(directions + get_global_id(2));
  if (line >= d.n_lines || step >= d.n_steps) return;
  float x, y;
  sweep_position(d, line, step, &x, &y);
  // Sample unconditionally (reads are clamped into the field), then mask: a call under a
  // condition keeps PoCL from vectorising.
  float sampled = sample_height(heights, width, height, x, y);
  float h = inside_field(x, y, width, height) ? sampled : NAN;
  // Two scalar stores rather than one float2 store, for the vectoriser.
  __global float* entry = (__global float*)(lines + line_entry(d, line, step));
  entry[0] = h;
  entry[1] = -1.0f;
}

#endif  // HFVIS_SWEEP_FRAMEWORK_CL
