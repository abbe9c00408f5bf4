// horizon.cl: horizons by the convex-hull-stack sweep (Timonen & Westerholm 2010,
// Algorithm 1) on lines through the pixel centres, reduced straight into the requested
// outputs, and the naive per-pixel ray march (the baseline and oracle).
//
// The sweep (horizon_lattice): a direction is a primitive integer step (a, b) in pixel
// axes. Every pixel centre lies on exactly one line of that direction, so every receiver is
// a sample of the line through its own centre, and the hull stack gives the horizon of the
// receiver's own ray from its own height. The line's samples between consecutive pixel
// centres (receivers) are where it crosses grid columns and rows, exact heights of the
// bilinear surface, and points between crossings; src/lattice_geometry.hpp builds the
// per-period table. Each receiver also takes the exact limit of its ray's elevation at
// t -> 0 (the surface's slope along the ray in its first cell): along a ray from a grid
// point the bilinear surface is a quadratic in the first cell, so (h(t) - h0) / t is linear
// there and its supremum is that limit or the first crossing, which is a sample.
//
// Heights arrive offset and z-scaled (h' = (h - lowest) * z_scale) so that tilted planes at
// large offsets keep their precision; NaN = nodata.
//
// Compile-time parameters, besides those of sweep_framework.cl:
//   HFVIS_WANT_ANGLES, HFVIS_WANT_DISTANCES  write the direction's planes
//   HFVIS_WANT_SVF, HFVIS_WANT_AO            accumulate sky-view / ambient occlusion terms
#include "sweep_framework.cl"
#include "fast_math.cl"

#ifndef HFVIS_WANT_ANGLES
#define HFVIS_WANT_ANGLES 1
#endif
#ifndef HFVIS_WANT_DISTANCES
#define HFVIS_WANT_DISTANCES 1
#endif
#ifndef HFVIS_WANT_SVF
#define HFVIS_WANT_SVF 1
#endif
#ifndef HFVIS_WANT_AO
#define HFVIS_WANT_AO 1
#endif

// Unit normal at pixel (c, r): the normalised sum of the unnormalised normals of the (up to)
// four quads around it (Timonen & Westerholm 2010, Sec. 7), in ground units; quads touching nodata
// or the border are left out; (0, 0, 1) when none is left.
HFVIS_INLINE void surface_normal(__global const float* heights, int width, int height, int c, int r, float h,
                                float cell_x, float cell_y, float* nx, float* ny, float* nz) {
  // Straight-line scalar code (clamped reads, masked sums) so that PoCL vectorises callers.
  float sx_sum = 0.0f, sy_sum = 0.0f, sz_sum = 0.0f;
  for (int q = 0; q < 4; ++q) {
    int sx = (q & 1) ? 1 : -1, sy = (q & 2) ? 1 : -1;
    int cx = c + sx, ry = r + sy;
    int inside = cx >= 0 && cx < width && ry >= 0 && ry < height;
    float hx = heights[r * width + clamp(cx, 0, width - 1)];
    float hy = heights[clamp(ry, 0, height - 1) * width + c];
    float gx = (hx - h) / ((float)sx * cell_x);
    float gy = (hy - h) / ((float)sy * cell_y);
    int use = inside && !isnan(hx) && !isnan(hy);
    sx_sum += use ? -gx : 0.0f;
    sy_sum += use ? -gy : 0.0f;
    sz_sum += use ? 1.0f : 0.0f;
  }
  float length = sqrt(sx_sum * sx_sum + sy_sum * sy_sum + sz_sum * sz_sum);
  int any = sz_sum > 0.0f;
  *nx = any ? sx_sum / length : 0.0f;
  *ny = any ? sy_sum / length : 0.0f;
  *nz = any ? sz_sum / length : 1.0f;
}

// Every pixel's unit normal as (x, y, z, 0), one 16-byte load per receiver, for ambient
// occlusion. Global size: (W, H) rounded up.
__kernel void pixel_normals(__global const float* heights, int width, int height, float cell_x, float cell_y,
                            __global float4* normals) {
  int c = get_global_id(0), r = get_global_id(1);
  if (c >= width || r >= height) return;
  const uint pixel = (uint)(r * width + c);
  float nx, ny, nz;
  surface_normal(heights, width, height, c, r, heights[pixel], cell_x, cell_y, &nx, &ny, &nz);
  normals[pixel] = (float4)(nx, ny, nz, 0.0f);
}

// Uniform-sky irradiance of one azimuthal swath (Eq. 5 of Timonen & Westerholm 2010) of
// width 2 pi * weight, normalised so that a flat plane sums to 1 over a run's swaths, for a
// horizon of slope rise / run (found 0: none, elevation -pi/2). With elevation e and zenith
// angle z = pi/2 - e, Eq. 5's sin^2 z = cos^2 e = 1 / (1 + x^2) and sin 2z / 2 = x cos^2 e for
// x = tan e, so only e itself needs an arctangent. The sky behind the surface (N . e < 0)
// does not count: the horizon is at least the tangent plane's slope -toward / nz in this
// azimuth. swath = sin(pi weight) / pi, per direction.
HFVIS_INLINE float ambient_term(int found, float rise, float run, float4 n, float cos_az, float sin_az, float weight,
                                float swath) {
  float toward = n.x * cos_az + n.y * sin_az;
  int behind = !found || rise * n.z < -toward * run;
  float x = behind ? -toward / n.z : rise / run;
  float cos2 = 1.0f / (1.0f + x * x);
  return n.z * weight * cos2 + swath * (0.5f * HFVIS_PI_F - hf_atan(x) - x * cos2) * toward;
}

// What one direction contributes at one receiver. Shared by the sweep and the naive march
// so both reduce identically. Each launch runs one direction and every pixel is written by
// one work-item of it, so the read-modify-writes of the sums need no atomics.
typedef struct {
  float cos_azimuth, sin_azimuth;  // the direction on the ground
  float weight;                    // its share of the circle of azimuth
  float swath;                     // sin(pi weight) / pi (ambient_term)
  uint plane;                      // first entry of its planes in `angles` / `distances`
} DirectionOutputs;

// The horizon arrives as the slope rise / run of its elevation (run > 0; `found` 0 when
// no point casts one: elevation -pi/2). The sky-view term sin(max(0, elevation)) is
// rise / sqrt(rise^2 + run^2) for a rising horizon, so the angle itself is only computed
// where an output needs it.
HFVIS_INLINE void emit_direction(uint pixel, int nodata, int found, float rise, float run, float distance,
                                 const DirectionOutputs o, __global const float4* normals,
                                 __global float* angles, __global float* distances, __global float* svf_sum,
                                 __global float* ao_sum) {
#if HFVIS_WANT_ANGLES
  angles[o.plane + pixel] = nodata ? NAN : (found ? hf_atan(rise / run) : -0.5f * HFVIS_PI_F);
#endif
#if HFVIS_WANT_DISTANCES
  distances[o.plane + pixel] = nodata ? NAN : distance;
#endif
#if HFVIS_WANT_SVF
  float sky = found && rise > 0.0f ? rise / sqrt(rise * rise + run * run) : 0.0f;
  svf_sum[pixel] = nodata ? NAN : svf_sum[pixel] + o.weight * sky;
#endif
#if HFVIS_WANT_AO
  float term = ambient_term(found, rise, run, normals[pixel], o.cos_azimuth, o.sin_azimuth, o.weight, o.swath);
  ao_sum[pixel] = nodata ? NAN : ao_sum[pixel] + term;
#endif
}

// One sample of a period (src/lattice_geometry.hpp, struct LatticeSample): nine 4-byte
// members, read field by field.
typedef struct {
  float tau;       // pixels from the period's receiver toward +(a, b)
  int ox, oy;      // the cell's lower corner, relative to the receiver
  int ex, ey;      // 1 where the sample is strictly inside the cell along x (y)
  float w00, w10, w01, w11;  // bilinear weights of the cell's corners
} LatticeSample;

// Height of the bilinear surface at a lattice sample whose cell corner is at entry `at`;
// with nodata, only the valid corners of positive weight count, renormalised (NaN when
// none). Crossing samples have ex or ey 0: their zero-weight corners repeat a used one.
HFVIS_INLINE float lattice_height(__global const float* heights, uint at, uint right, uint down, float w00, float w10,
                                  float w01, float w11) {
  float h00 = heights[at], h10 = heights[at + right], h01 = heights[at + down], h11 = heights[at + down + right];
  float plain = w00 * h00 + w10 * h10 + w01 * h01 + w11 * h11;
#if HFVIS_HAS_NODATA
  int v00 = w00 > 0.0f && !isnan(h00), v10 = w10 > 0.0f && !isnan(h10);
  int v01 = w01 > 0.0f && !isnan(h01), v11 = w11 > 0.0f && !isnan(h11);
  float sum = (v00 ? w00 * h00 : 0.0f) + (v10 ? w10 * h10 : 0.0f) + (v01 ? w01 * h01 : 0.0f) + (v11 ? w11 * h11 : 0.0f);
  float weight = (v00 ? w00 : 0.0f) + (v10 ? w10 : 0.0f) + (v01 ? w01 : 0.0f) + (v11 ? w11 : 0.0f);
  return isnan(plain) ? (weight > 0.0f ? sum / weight : NAN) : plain;
#else
  return plain;
#endif
}

// The exact limit of receiver (c, r)'s elevation slope at t -> 0 along (a, b): the bilinear
// surface's directional derivative into the first cell, from the receiver's height h and
// its neighbours along the two axes, as a rise over the period |(a, b)| (the caller's run).
// NaN where the ray leaves the field at once or a needed neighbour is nodata.
HFVIS_INLINE float near_rise(__global const float* heights, int width, int height, int c, int r, float h, int a,
                             int b) {
  int sx = a > 0 ? 1 : (a < 0 ? -1 : 0), sy = b > 0 ? 1 : (b < 0 ? -1 : 0);
  int leaves = c + sx < 0 || c + sx >= width || r + sy < 0 || r + sy >= height;
  float hx = heights[r * width + clamp(c + sx, 0, width - 1)];
  float hy = heights[clamp(r + sy, 0, height - 1) * width + c];
  float rise = (hx - h) * (float)abs(a) + (hy - h) * (float)abs(b);
  return leaves ? NAN : rise;
}

// One step of Algorithm 1 (Timonen & Westerholm 2010) for a sample of height h at
// position `here` along the line: pops the stack while the entry below the top casts at
// least as steep a slope on the sample as the top (so the farther wins ties); the top that
// remains is its horizon occluder, whose rise above the sample and distance along the line
// (pixels) it returns in *rise, *run (run 0: none). Then pushes the sample. The top entry
// is kept in registers (*top_h, *top_p) as well as in the stack.
HFVIS_INLINE void hull_stack_step(__global float2* stack, uint stride, uint* size, float* top_h, float* top_p,
                                  float h, float here, float* rise, float* run) {
  uint n = *size;
  float v1h = *top_h - h, v1d = here - *top_p;
  while (n > 1) {
    const float2 below = stack[(n - 2) * stride];
    const float v2h = below.x - h, v2d = here - below.y;
    if (v2h * v1d >= v1h * v2d) {
      v1h = v2h;
      v1d = v2d;
      *top_h = below.x;
      *top_p = below.y;
      --n;
    } else {
      break;
    }
  }
  *rise = v1h;
  *run = n > 0 ? v1d : 0.0f;
  stack[n * stride] = (float2)(h, here);
  *top_h = h;
  *top_p = here;
  *size = n + 1;
}

// The sweep of one direction (a, b): one work-item per line, from the line's far end toward
// -(a, b). Line j's farthest receiver is lines[j] = (col, row, receivers, stack); receiver
// i sits at (col - i a, row - i b). Per receiver, the period's samples farther along the
// line come first (samples[0 .. n_samples - 2], farthest first), then the receiver itself,
// each through hull_stack_step. Only the first period can reach outside the field (the
// others lie between two receivers, inside it), so only it tests; samples outside the
// field or without height are absent. Stack entry k of a line is (height, position along
// the line in pixels from its far end) at stacks[stack + k * stride]; the capacity is every
// sample of its periods. period_ground = period * ground_per_pixel, the ground length of a
// period. Preconditions: lines of this launch only; stride 1 (line-major) or the launch's
// line count (step-major). Global size: n_lines rounded up; any local size.
__kernel void horizon_lattice(__global const float* heights, int width, int height,
                              __global const int4* lines, int n_lines, __global const LatticeSample* samples,
                              int n_samples, int a, int b, float period, float ground_per_pixel, float period_ground,
                              float cos_azimuth, float sin_azimuth, float weight, float swath, uint plane,
                              __global float2* stacks, uint stride, __global const float4* normals,
                              __global float* angles, __global float* distances, __global float* svf_sum,
                              __global float* ao_sum) {
  const int j = get_global_id(0);
  if (j >= n_lines) return;
  const int4 line = lines[j];
  const DirectionOutputs outputs = {cos_azimuth, sin_azimuth, weight, swath, plane};
  __global float2* stack = stacks + line.w;
  int c = line.x, r = line.y;
  uint n = 0;                        // stack size
  float top_h = 0.0f, top_p = 0.0f;  // the top entry
  float rise, run;
  for (int i = 0; i < line.z; ++i, c -= a, r -= b) {
    const float base = (float)i * period;  // the receiver's position along the line
    for (int q = 0; q < n_samples - 1; ++q) {
      __global const LatticeSample* s = samples + q;
      const int x0 = c + s->ox, y0 = r + s->oy, ex = s->ex, ey = s->ey;
      if (i == 0 && (x0 < 0 || x0 + ex > width - 1 || y0 < 0 || y0 + ey > height - 1)) continue;
      const float h = lattice_height(heights, (uint)(y0 * width + x0), (uint)ex, (uint)(ey * width), s->w00, s->w10,
                                     s->w01, s->w11);
#if HFVIS_HAS_NODATA
      if (isnan(h)) continue;
#endif
      hull_stack_step(stack, stride, &n, &top_h, &top_p, h, base - s->tau, &rise, &run);
    }
    const uint pixel = (uint)(r * width + c);
    const float h = heights[pixel];
#if HFVIS_HAS_NODATA
    if (isnan(h)) {
      emit_direction(pixel, 1, 0, 0.0f, 1.0f, 0.0f, outputs, normals, angles, distances, svf_sum, ao_sum);
      continue;
    }
#endif
    hull_stack_step(stack, stride, &n, &top_h, &top_p, h, base, &rise, &run);
    // The steeper of the hull's occluder and the limit at the receiver, compared without a
    // division (both runs are positive); the occluder wins ties (it is the farther point
    // casting that elevation).
    const float near = near_rise(heights, width, height, c, r, h, a, b);
    const float ground = run * ground_per_pixel;
    const int has_far = run > 0.0f, has_near = !isnan(near);
    const int use_near = has_near && (!has_far || near * ground > rise * period_ground);
    const float distance = has_far && !use_near ? ground : 0.0f;
    emit_direction(pixel, 0, has_far || has_near, use_near ? near : rise, use_near ? period_ground : ground, distance,
                   outputs, normals, angles, distances, svf_sum, ao_sum);
  }
}

// Naive method (Timonen 2013, Sec. 1): for every pixel, march the ray in steps of
// step_length pixels along (dir_x, dir_y), sample bilinearly and keep the steepest slope.
// One direction per launch, its geometry passed as arguments (uniform for certain, no
// per-step loads). The trip count is the same for the whole work-group (the longest ray of
// the group's tile, in closed form because the exit distance separates into a column and a
// row term), and a barrier ends every step: PoCL runs the work-items inside each step, the
// one loop it vectorises (the march ran 5x faster that way on PoCL); samples past a
// pixel's own exit are masked. Global size: (W, H) rounded up to the local size (the tile).
__kernel void horizon_naive(__global const float* heights, int width, int height, float dir_x, float dir_y,
                            float step_length, float ground_per_pixel, float cos_azimuth, float sin_azimuth,
                            float weight, float swath, uint plane, __global const float4* normals, __global float* angles,
                            __global float* distances, __global float* svf_sum, __global float* ao_sum) {
  int c = get_global_id(0), r = get_global_id(1);
  int c_lo = get_group_id(0) * get_local_size(0), r_lo = get_group_id(1) * get_local_size(1);
  int c_hi = min(c_lo + (int)get_local_size(0), width) - 1;
  int r_hi = min(r_lo + (int)get_local_size(1), height) - 1;
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  const float h = heights[pixel];
  const float far = (float)(width + height);
  float reach_x = dir_x > 0.0f ? ((float)(width - 1) - (float)c_lo) / dir_x : dir_x < 0.0f ? (float)c_hi / -dir_x : far;
  float reach_y = dir_y > 0.0f ? ((float)(height - 1) - (float)r_lo) / dir_y : dir_y < 0.0f ? (float)r_hi / -dir_y : far;
  const int steps = (int)(hf_min(hf_min(reach_x, reach_y), far) / step_length) + 1;
  float best_rise = 0.0f;  // height gain to the steepest sample so far
  int best_step = 0;       // its step, 0 = none yet
  for (int i = 1; i <= steps; ++i) {
    float t = (float)i * step_length;
    float px = (float)cc + t * dir_x, py = (float)rr + t * dir_y;
    float q = sample_height(heights, width, height, px, py);
    float rise = q - h;
    // rise / i >= best_rise / best_step without a division; ties go to the farther sample.
    int better = inside_field(px, py, width, height) & !isnan(q) &
                 ((best_step == 0) | (rise * (float)best_step >= best_rise * (float)i));
    best_rise = better ? rise : best_rise;
    best_step = better ? i : best_step;
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  const float ground = (float)best_step * step_length * ground_per_pixel;
  const float distance = best_step > 0 ? ground : 0.0f;
  const DirectionOutputs outputs = {cos_azimuth, sin_azimuth, weight, swath, plane};
  if (valid)
    emit_direction(pixel, isnan(h), best_step > 0, best_rise, ground, distance, outputs, normals, angles, distances,
                   svf_sum, ao_sum);
}
