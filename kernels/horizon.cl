// horizon.cl: horizons by the convex-hull-stack sweep (Timonen & Westerholm 2010,
// Algorithm 1), the reduction that rotates line buffers back onto the grid and reduces
// them to the requested outputs, and the naive per-pixel ray march (baseline and oracle).
//
// Heights arrive offset and z-scaled (h' = (h - reference) * z_scale) so that tilted
// planes at large offsets keep their precision; NaN = nodata.
//
// Compile-time parameters, besides those of sweep_framework.cl:
//   HFVIS_WANT_ANGLES, HFVIS_WANT_DISTANCES  store per-direction planes of the batch
//   HFVIS_WANT_SVF, HFVIS_WANT_AO            accumulate sky-view / ambient occlusion terms
//   HFVIS_DIRECTIONS                         K, the directions of the whole run
//   HFVIS_NEAR_SAMPLES                       exact near-field samples per receiver (>= 1)
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
#ifndef HFVIS_DIRECTIONS
#define HFVIS_DIRECTIONS 64
#endif
#define HFVIS_NEAR_MARGIN 4e-6f  // radians: rounding of hf_atan and of the interpolation
#ifndef HFVIS_NEAR_SAMPLES
#define HFVIS_NEAR_SAMPLES 4  // receiver's own ray samples over its first step (reduction)
#endif


// One step of Algorithm 1 (Timonen & Westerholm 2010) on one line: reads the presampled
// height at *entry and writes, in place, the occluder that casts its horizon:
// (occluder height - sample height, occluder step), or (NaN, -1) when nothing farther along
// the line has been seen. Pops while the second stack entry casts at least as steep a slope
// on the new sample as the top one; the top that remains is the occluder.
HFVIS_INLINE void hull_stack_step(__global float2* entry, __global float2* stack, uint stride, uint* size,
                                  int step) {
  float h = entry->x;
  if (isnan(h)) {
    *entry = (float2)(NAN, -1.0f);
    return;
  }
  float2 occluder = (float2)(NAN, -1.0f);
  float here = (float)step;
  uint n = *size;
  if (n > 0) {
    float2 top = stack[(n - 1) * stride];
    float v1h = top.x - h;
    float v1d = here - top.y;
    while (n > 1) {
      float2 below = stack[(n - 2) * stride];
      float v2h = below.x - h;
      float v2d = here - below.y;
      if (v2h * v1d >= v1h * v2d) {
        top = below;
        v1h = v2h;
        v1d = v2d;
        --n;
      } else {
        break;
      }
    }
    occluder = top;
  }
  stack[n * stride] = (float2)(h, here);
  *size = n + 1;
  *entry = (float2)(occluder.x - h, occluder.y);
}

// Hull-stack sweep: one work-item per line. The stack of line j holds (height, step)
// entries in the line's own slots of the stacks buffer, depth k at line_entry(d, j, k): the
// depth never exceeds the line's sample count, so the stack buffer is as large as the line
// buffer. (Interleaving 2, 4 or 8 lines per work-item to overlap their serial chains was
// measured slower on PoCL, so each work-item keeps one line.)
// Global size: (max lines, directions in batch).
__kernel void horizon_sweep(__global const SweepDirection* directions, __global float2* lines,
                            __global float2* stacks) {
  const int line = get_global_id(0);
  const SweepDirection d = load_direction(directions + get_global_id(1));
  if (line >= d.n_lines) return;
  const uint stride = line_stride(d);
  __global float2* entry = lines + line_entry(d, line, 0);
  __global float2* stack = stacks + line_entry(d, line, 0);
  uint size = 0;
  for (int step = 0; step < d.n_steps; ++step, entry += stride) hull_stack_step(entry, stack, stride, &size, step);
}

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

// Uniform-sky irradiance of one azimuthal swath (Eq. 5 of Timonen & Westerholm 2010) for
// horizon elevation `elevation`, normalised so that a flat plane sums to 1 over K swaths.
// The zenith angle is clamped where the sky falls behind the surface (N . e = 0).
HFVIS_INLINE float ambient_term(float elevation, float nx, float ny, float nz, float cos_az, float sin_az) {
  float toward = nx * cos_az + ny * sin_az;
  float zenith = 0.5f * HFVIS_PI_F - elevation;
  zenith = fmin(zenith, 0.5f * HFVIS_PI_F + hf_atan(toward / nz));
  float s = hf_sin(zenith);
  return nz / (float)HFVIS_DIRECTIONS * s * s +
         hf_sin(HFVIS_PI_F / (float)HFVIS_DIRECTIONS) / HFVIS_PI_F * (zenith - 0.5f * hf_sin(2.0f * zenith)) * toward;
}

// Writes or accumulates one direction's outputs at one pixel; shared by the sweep
// reduction and the naive kernel so both reduce identically.
HFVIS_INLINE void emit_direction(int b, uint pixel, uint plane, float elevation, float distance, float nx,
                                 float ny, float nz, const SweepDirection d, __global float* angles, __global float* distances,
                           float* svf, float* ao) {
#if HFVIS_WANT_ANGLES
  angles[(uint)b * plane + pixel] = elevation;
#endif
#if HFVIS_WANT_DISTANCES
  distances[(uint)b * plane + pixel] = distance;
#endif
  // Only what is asked for: PoCL keeps unused terms alive across the barriers.
#if HFVIS_WANT_SVF
  *svf += hf_sin(fmax(0.0f, elevation));
#endif
#if HFVIS_WANT_AO
  *ao += ambient_term(elevation, nx, ny, nz, d.cos_azimuth, d.sin_azimuth);
#endif
}

// Adds the batch's sums to the run's accumulators; NaN at nodata receivers.
HFVIS_INLINE void accumulate_pixel(uint pixel, int nodata, float svf, float ao, __global float* svf_sum,
                             __global float* ao_sum) {
#if HFVIS_WANT_SVF
  svf_sum[pixel] = nodata ? NAN : svf_sum[pixel] + svf;
#endif
#if HFVIS_WANT_AO
  ao_sum[pixel] = nodata ? NAN : ao_sum[pixel] + ao;
#endif
}

// Reduction: for every receiver pixel and every direction of the batch, bilinearly
// interpolates the horizons of the (up to) four surrounding (line, step) entries, each
// exact for its own sample, and writes or accumulates the requested outputs. (Seeing the
// neighbours' occluders from the receiver instead would be biased by the lateral offset
// between line and receiver on every slope, and unstable where an occluder is nearly
// beside the receiver.) Entries without an occluder are left out; with none left, the
// horizon is -pi/2 (the ray leaves the field at once). Global size: (W, H) rounded up.
__kernel void horizon_reduce(__global const float* heights, int width, int height, float cell_x,
                             float cell_y, __global const SweepDirection* directions, int batch_size,
                             __global const float2* lines, __global float* angles, __global float* distances,
                             __global float* svf_sum, __global float* ao_sum) {
  // Straight-line code throughout (clamped reads, masked sums, no early exits): PoCL only
  // vectorises across work-items where control flow is uniform, and this kernel runs its
  // transcendentals once per pixel and direction.
  int c = get_global_id(0), r = get_global_id(1);
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  const uint plane = (uint)(width * height);
  float h = heights[pixel];
  float nx = 0.0f, ny = 0.0f, nz = 1.0f;
#if HFVIS_WANT_AO
  surface_normal(heights, width, height, cc, rr, h, cell_x, cell_y, &nx, &ny, &nz);
#endif
  float svf = 0.0f, ao = 0.0f;
  for (int b = 0; b < batch_size; ++b) {
    // The barrier (every work-item reaches it: the loop is uniform) makes PoCL run the
    // work-items inside each iteration rather than each work-item's whole loop in turn,
    // and only that innermost work-item loop gets vectorised: 3x faster on PoCL.
    barrier(CLK_LOCAL_MEM_FENCE);
    const SweepDirection d = load_direction(directions + b);
    float x = (float)cc, y = (float)rr;
    int j0, i0;
    float fu, fv;
    receiver_cell(d, x, y, &j0, &i0, &fu, &fv);
    float weight = 0.0f, angle_sum = 0.0f, distance_sum = 0.0f;
    for (int k = 0; k < 4; ++k) {
      float w;
      int i;
      __global const float* occ = (__global const float*)(lines + cell_corner(d, j0, i0, fu, fv, k, &w, &i));
      float rise = occ[0], occ_step = occ[1];  // scalar loads, for the vectoriser
      int use = w > 0.0f && occ_step >= 0.0f;
      float ground = ((float)i - occ_step) * d.step_length * d.ground_per_pixel;
      float angle = hf_atan2_ahead(rise, ground);
      weight += use ? w : 0.0f;
      angle_sum += use ? w * angle : 0.0f;
      distance_sum += use ? w * ground : 0.0f;
    }
    // Exact near field: the surrounding line samples lie up to a line spacing away and
    // their own first steps differ from the receiver's, where the bilinear surface can rise
    // steeply; that was the larger part of the sweep's error (fractal 256^2, K = 16: mean
    // 1.17 -> 0.30 deg against a 4x-sampled naive march, HorizonOptions::near_field_samples
    // 1 -> 4). The receiver's own ray, sampled
    // at HFVIS_NEAR_SAMPLES points over its first step, bounds the horizon from below, so
    // the steeper of the two wins. It also decides at the field's edges: a ray that leaves
    // the field before its first near sample has horizon -pi/2.
    float near_slope = 0.0f, near_t = 0.0f;  // steepest rise per pixel length, and where
    int near_found = 0, ray_has_sample = 0;
    for (int q = 1; q <= HFVIS_NEAR_SAMPLES; ++q) {
      float t = (float)q * (d.step_length / (float)HFVIS_NEAR_SAMPLES);
      float qx = x + t * d.dir_x, qy = y + t * d.dir_y;
      int inside = inside_field(qx, qy, width, height);
      float slope = (sample_height(heights, width, height, qx, qy) - h) / t;
      int better = inside && !isnan(slope) && (!near_found || slope >= near_slope);  // farther wins ties
      near_slope = better ? slope : near_slope;
      near_t = better ? t : near_t;
      near_found = near_found || better;
      ray_has_sample = ray_has_sample || (q == 1 && inside);
    }
    float near_elevation = hf_atan(near_slope / d.ground_per_pixel);
    float elevation = weight > 0.0f ? angle_sum / weight : -0.5f * HFVIS_PI_F;
    float distance = weight > 0.0f ? distance_sum / weight : 0.0f;
    // Steeper by more than the two paths' rounding: where they agree (a straight flank)
    // the line samples' farther occluder stays, as on the hull.
    int use_near = near_found && (!(weight > 0.0f) || near_elevation > elevation + HFVIS_NEAR_MARGIN);
    elevation = use_near ? near_elevation : elevation;
    distance = use_near ? near_t * d.ground_per_pixel : distance;
    elevation = ray_has_sample ? elevation : -0.5f * HFVIS_PI_F;
    distance = ray_has_sample ? distance : 0.0f;
    elevation = isnan(h) ? NAN : elevation;
    distance = isnan(h) ? NAN : distance;
    if (valid) emit_direction(b, pixel, plane, elevation, distance, nx, ny, nz, d, angles, distances, &svf, &ao);
  }
  if (valid) accumulate_pixel(pixel, isnan(h), svf, ao, svf_sum, ao_sum);
}

// Naive method (Timonen 2013, Sec. 1): for every pixel, march the ray in steps of
// step_length pixels, sample bilinearly and keep the steepest slope. The trip count is
// the same for the whole work-group (the longest ray of the group's tile, found in closed
// form because the exit distance separates into a column and a row term), so the march
// can run in lock-step across work-items and vectorise; samples outside the field are
// masked.
// Global size: (W, H) rounded up to the local size; the tile is the work-group.
__kernel void horizon_naive(__global const float* heights, int width, int height, float cell_x, float cell_y,
                            __global const SweepDirection* directions, int batch_size,
                            __global float* angles, __global float* distances, __global float* svf_sum,
                            __global float* ao_sum) {
  int c = get_global_id(0), r = get_global_id(1);
  // The tile's extent, clamped to the field (work-items past the edge still march, so that
  // the whole group runs the same loop, and only skip the writes).
  int c_lo = get_group_id(0) * get_local_size(0), r_lo = get_group_id(1) * get_local_size(1);
  int c_hi = min(c_lo + (int)get_local_size(0), width) - 1;
  int r_hi = min(r_lo + (int)get_local_size(1), height) - 1;
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  const uint plane = (uint)(width * height);
  float h = heights[pixel];
  float nx = 0.0f, ny = 0.0f, nz = 1.0f;
#if HFVIS_WANT_AO
  surface_normal(heights, width, height, cc, rr, h, cell_x, cell_y, &nx, &ny, &nz);
#endif
  float svf = 0.0f, ao = 0.0f;
  for (int b = 0; b < batch_size; ++b) {
    const SweepDirection d = load_direction(directions + b);
    const float far = (float)(width + height);
    float reach_x = d.dir_x > 0.0f ? ((float)(width - 1) - (float)c_lo) / d.dir_x
                    : d.dir_x < 0.0f ? (float)c_hi / -d.dir_x : far;
    float reach_y = d.dir_y > 0.0f ? ((float)(height - 1) - (float)r_lo) / d.dir_y
                    : d.dir_y < 0.0f ? (float)r_hi / -d.dir_y : far;
    int steps = (int)(fmin(fmin(reach_x, reach_y), far) * d.samples_per_unit) + 1;
    float best_rise = 0.0f;  // height gain to the steepest sample so far
    int best_step = 0;       // its step, 0 = none yet
    for (int i = 1; i <= steps; ++i) {
      // `steps` is the same for the whole work-group, so every work-item reaches this
      // barrier; it makes PoCL run the work-items inside each step, the one loop it
      // vectorises: 5x faster there (1.05 -> 0.20 s, 256^2 fractal, K = 8, one thread).
      barrier(CLK_LOCAL_MEM_FENCE);
      float t = (float)i * d.step_length;
      float px = (float)cc + t * d.dir_x, py = (float)rr + t * d.dir_y;
      float q = sample_height(heights, width, height, px, py);
      float rise = q - h;
      // rise / i >= best_rise / best_step, decided without division as the sweep does;
      // on ties the farther sample wins, as on the sweep's hull.
      int better = inside_field(px, py, width, height) && !isnan(q) &&
                   (best_step == 0 || rise * (float)best_step >= best_rise * (float)i);
      best_rise = better ? rise : best_rise;
      best_step = better ? i : best_step;
    }
    float ground = (float)best_step * d.step_length * d.ground_per_pixel;
    float elevation = best_step > 0 ? hf_atan2_ahead(best_rise, ground) : -0.5f * HFVIS_PI_F;
    float distance = best_step > 0 ? ground : 0.0f;
    if (isnan(h)) elevation = distance = NAN;
    if (valid) emit_direction(b, pixel, plane, elevation, distance, nx, ny, nz, d, angles, distances, &svf, &ao);
  }
  if (valid) accumulate_pixel(pixel, isnan(h), svf, ao, svf_sum, ao_sum);
}
