// sweep_framework.cl: what every sweep kernel shares: the per-direction line geometry,
// bilinear height sampling with the nodata policy, and the line presampling pass.
//
// Geometry (pixel axes, x = column, y = row; pixel (c, r) at (c, r)): lines run along the
// unit direction `dir`; line j lies at perpendicular offset (line_first + j) * line_spacing
// along `perp`; step i of every line lies at t = (step_top - i) * step_length along `dir`,
// so step 0 is the far end and a line is swept toward -dir. All lines of a direction share
// the step lattice, so the line buffer entry (step i, line j) sits at
// buffer_offset + i * n_lines + j and adjacent work-items write adjacent addresses.
//
// Compile-time parameters (prepended #defines; every kernel compiles with the defaults):
//   HFVIS_HAS_NODATA  the field holds NaN heights: bilinear samples renormalise over the
//                     valid corners (0 = the faster path without checks)
//   HFVIS_EDGE_EPS    how far outside [0, W-1] x [0, H-1] (pixels) a sample still counts as
//                     inside (absorbs rounding of directions that are exactly axis-aligned)
#ifndef HFVIS_SWEEP_FRAMEWORK_CL
#define HFVIS_SWEEP_FRAMEWORK_CL

// Rounding must be identical in the scalar C++ references (built with -ffp-contract=off).
#pragma OPENCL FP_CONTRACT OFF

#ifndef HFVIS_HAS_NODATA
#define HFVIS_HAS_NODATA 1
#endif
#ifndef HFVIS_EDGE_EPS
#define HFVIS_EDGE_EPS 1e-3f
#endif

// One direction's sweep geometry. Must match struct SweepDirection in
// src/sweep_geometry.hpp: sixteen 4-byte members, no padding.
typedef struct {
  float dir_x, dir_y;              // unit line direction in pixel axes
  float perp_x, perp_y;            // (-dir_y, dir_x)
  float line_spacing;              // pixels between lines (1 / lines_per_unit)
  float lines_per_unit;
  float step_length;               // pixels between samples (1 / samples_per_unit)
  float samples_per_unit;
  float ground_per_pixel;          // ground length of one pixel length along dir
  float cos_azimuth, sin_azimuth;  // the direction on the ground, for shading
  int line_first;
  int n_lines;
  int step_top;
  int n_steps;
  uint buffer_offset;              // first entry of this direction in the line buffer
} SweepDirection;

inline float2 sweep_position(const SweepDirection d, int line, int step) {
  float s = (float)(d.line_first + line) * d.line_spacing;
  float t = (float)(d.step_top - step) * d.step_length;
  return (float2)(s * d.perp_x + t * d.dir_x, s * d.perp_y + t * d.dir_y);
}

inline int inside_field(float2 p, int width, int height) {
  return p.x >= -HFVIS_EDGE_EPS && p.x <= (float)(width - 1) + HFVIS_EDGE_EPS && p.y >= -HFVIS_EDGE_EPS &&
         p.y <= (float)(height - 1) + HFVIS_EDGE_EPS;
}

// Bilinear height at p (clamped into the field). With nodata, only the valid corners
// count and their weights are renormalised; NaN when no corner with weight is valid.
inline float sample_height(__global const float* heights, int width, int height, float2 p) {
  float x = clamp(p.x, 0.0f, (float)(width - 1));
  float y = clamp(p.y, 0.0f, (float)(height - 1));
  int x0 = min((int)floor(x), max(width - 2, 0));
  int y0 = min((int)floor(y), max(height - 2, 0));
  int x1 = min(x0 + 1, width - 1);
  int y1 = min(y0 + 1, height - 1);
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
#if HFVIS_HAS_NODATA
  if (isnan(h00) || isnan(h10) || isnan(h01) || isnan(h11)) {
    float sum = 0.0f, weight = 0.0f;
    if (!isnan(h00)) { sum += w00 * h00; weight += w00; }
    if (!isnan(h10)) { sum += w10 * h10; weight += w10; }
    if (!isnan(h01)) { sum += w01 * h01; weight += w01; }
    if (!isnan(h11)) { sum += w11 * h11; weight += w11; }
    return weight > 0.0f ? sum / weight : NAN;
  }
#endif
  return w00 * h00 + w10 * h10 + w01 * h01 + w11 * h11;
}

// Presampling pass: the height at every (step, line) of the batch's directions, NaN where
// the sample lies outside the field or has no valid corner. Uniform control flow, so
// PoCL vectorises it across lines; the sweep then only reads one float per step.
// Global size: (max lines, max steps, directions in batch), any local size.
__kernel void presample_lines(__global const float* heights, int width, int height,
                              __global const SweepDirection* directions, __global float2* lines) {
  int line = get_global_id(0);
  int step = get_global_id(1);
  const SweepDirection d = directions[get_global_id(2)];
  if (line >= d.n_lines || step >= d.n_steps) return;
  float2 p = sweep_position(d, line, step);
  float h = inside_field(p, width, height) ? sample_height(heights, width, height, p) : NAN;
  lines[d.buffer_offset + (uint)step * (uint)d.n_lines + (uint)line] = (float2)(h, -1.0f);
}

#endif  // HFVIS_SWEEP_FRAMEWORK_CL
