// horizon_baselines.cl: the per-pixel horizon methods the benchmark (bench/) sets against
// the hull-stack sweep: the ray march limited to a search radius (screen-space style; the
// naive march itself is the library's, kernels/horizon.cl), the march over a max-height pyramid with steps
// growing with distance (the level-of-detail scheme of Snyder & Nowrouzezahrai 2008 and
// Nowrouzezahrai & Snyder 2009), and a bandwidth floor that only reads heights and writes
// one value per pixel and direction. All write horizon elevation angles (radians) into
// per-direction planes of the batch, as horizon.cl does with HFVIS_WANT_ANGLES.
//
// Not part of the library: bench/CMakeLists.txt embeds it into hfvis_bench alone, which builds
// it on the library's context (ContextState::programFromSource). It includes the library's
// sweep framework by its path, so it compiles standalone with no -I.
//
// Preconditions: no nodata (every height finite; the benchmark's fields have none), width
// and height >= 2, heights offset and z-scaled as the library prepares them.
//
// Compile-time parameters (prepended #defines; every kernel compiles with the defaults):
//   HFVIS_RADIUS_STEPS   march at most this many samples per ray (0 = to the field's edge)
//   HFVIS_PYRAMID_NEAR   the pyramid march takes this many unit steps on the full-resolution
//                        surface, then HFVIS_PYRAMID_NEAR / 2 steps per octave of distance on
//                        ever coarser levels (step and texel size 2^level); even, >= 2
#include "../../kernels/shared/sweep_framework.cl"

#ifndef HFVIS_EDGE_EPS  // as in sweep_framework.cl: tolerance of "inside the field", pixels
#define HFVIS_EDGE_EPS 1e-3f
#endif
#ifndef HFVIS_RADIUS_STEPS
#define HFVIS_RADIUS_STEPS 0
#endif
#ifndef HFVIS_PYRAMID_NEAR
#define HFVIS_PYRAMID_NEAR 16
#endif

#define BASELINE_PI 3.14159265358979323846f

// The helpers below are this file's own (only SweepDirection, the host contract, comes from
// sweep_framework.cl), so the baselines stay fixed while the sweep's framework evolves.
// They are forced inline and straight-line scalar code: a call PoCL does not inline keeps the
// loop around it from being vectorised, and branches must be flattened before it can be.
#define BASELINE_INLINE inline __attribute__((always_inline))

BASELINE_INLINE int bl_inside(float x, float y, int width, int height) {
  // Bitwise & rather than &&, whose short-circuits become branches.
  return (x >= -HFVIS_EDGE_EPS) & (x <= (float)(width - 1) + HFVIS_EDGE_EPS) & (y >= -HFVIS_EDGE_EPS) &
         (y <= (float)(height - 1) + HFVIS_EDGE_EPS);
}

// Bilinear height at (px, py), clamped into the field; no nodata path (see preconditions).
BASELINE_INLINE float bl_bilinear(__global const float* heights, int width, int height, float px, float py) {
  float x = clamp(px, 0.0f, (float)(width - 1));
  float y = clamp(py, 0.0f, (float)(height - 1));
  int x0 = min((int)x, width - 2);  // x >= 0, so truncation is floor
  int y0 = min((int)y, height - 2);
  float fx = x - (float)x0;
  float fy = y - (float)y0;
  int at = y0 * width + x0;
  float h00 = heights[at], h10 = heights[at + 1], h01 = heights[at + width], h11 = heights[at + width + 1];
  float top = h00 + fx * (h10 - h00);
  float bottom = h01 + fx * (h11 - h01);
  return top + fy * (bottom - top);
}

// Keeps the steepest sample: rise / t >= best_rise / best_t decided without a division
// (ties go to the farther sample); masked, never skipped, so all lanes run the same code.
BASELINE_INLINE void bl_keep_steepest(float rise, float t, int inside, float* best_rise, float* best_t) {
  int better = inside & ((*best_t == 0.0f) | (rise * *best_t >= *best_rise * t));
  *best_rise = better ? rise : *best_rise;
  *best_t = better ? t : *best_t;
}

// atan(z) as straight-line code (Cephes atanf: two range reductions and a degree-9 odd
// polynomial, about 1e-7 relative error): the built-in atan2 is a call PoCL does not
// inline, which would keep the end of every march scalar.
BASELINE_INLINE float bl_atan(float z) {
  float a = fabs(z);
  int far = a > 2.414213562373095f, mid = a > 0.4142135623730950f;
  float x = far ? -1.0f / a : mid ? (a - 1.0f) / (a + 1.0f) : a;
  float base = far ? 0.5f * BASELINE_PI : mid ? 0.25f * BASELINE_PI : 0.0f;
  float x2 = x * x;
  float p = (((8.05374449538e-2f * x2 - 1.38776856032e-1f) * x2 + 1.99777106478e-1f) * x2 - 3.33329491539e-1f) * x2;
  float r = base + (p * x + x);
  return z < 0.0f ? -r : r;
}

// Horizon elevation from the steepest sample, or -pi/2 when no sample lay inside the field.
BASELINE_INLINE float bl_elevation(float best_rise, float best_t, float ground_per_pixel) {
  return best_t > 0.0f ? bl_atan(best_rise / (best_t * ground_per_pixel)) : -0.5f * BASELINE_PI;
}

// How the marches vectorise on PoCL (CPU): PoCL runs the work-items of a group in a loop
// around each region between barriers and lets LLVM vectorise that loop, which LLVM does
// only when it is innermost. A march loop without a barrier therefore ends up inside the
// work-item loop, scalar (and PoCL 3.1 did not insert its implicit loop barriers here, see
// bench/README.md). With a barrier at the end of each iteration of a loop whose trip count
// is the same for the whole group (the tile's longest ray), the work-item loop is the
// iteration's body: every step runs the group's pixels as vector lanes, samples past a
// pixel's own exit masked. The barrier is legal because every work-item of the group
// reaches it equally often, and it costs no synchronisation on a CPU.

// Radius-limited march (HFVIS_RADIUS_STEPS samples; 0 = to the field's edge, which the
// suite's checks compare with the library's naive kernel, kernels/horizon.cl): for every pixel, samples
// the bilinear surface every step_length pixels along (dir_x, dir_y) and keeps the
// steepest; writes the elevation to angles[plane_offset + pixel]. One direction per launch,
// its geometry passed as arguments (uniform for certain, no per-step loads).
// Global size: (W, H) rounded up to the local size; any local size (the tile).
__kernel void radius_march(__global const float* heights, int width, int height, float dir_x, float dir_y,
                           float step_length, float samples_per_unit, float ground_per_pixel,
                           __global float* angles, uint plane_offset) {
  int c = get_global_id(0), r = get_global_id(1);
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  const float h = heights[pixel];
  int steps = (int)(tile_reach(dir_x, dir_y, width, height) * samples_per_unit) + 1;
#if HFVIS_RADIUS_STEPS > 0
  steps = min(steps, HFVIS_RADIUS_STEPS);
#endif
  float best_rise = 0.0f, best_t = 0.0f;
  for (int n = 0; n < steps; ++n) {
    float t = (float)(n + 1) * step_length;
    float x = (float)cc + t * dir_x, y = (float)rr + t * dir_y;
    float rise = bl_bilinear(heights, width, height, x, y) - h;
    bl_keep_steepest(rise, t, bl_inside(x, y, width, height), &best_rise, &best_t);
    barrier(CLK_LOCAL_MEM_FENCE);  // one vectorised region per step (see above)
  }
  float elevation = bl_elevation(best_rise, best_t, ground_per_pixel);
  if (valid) angles[plane_offset + pixel] = elevation;
}

// One level of the max pyramid. Texel (i, j) of level l bounds the surface over the square
// [i, i + 1] x [j, j + 1] * 2^l (its edges shared with its neighbours), so it is the maximum
// of the level below over [2i, 2i + span] x [2j, 2j + span]: span 2 from the grid points of
// level 0 (three points per axis), span 1 between texel levels. Levels live at offsets in
// one buffer (sub-buffers would need aligned offsets). Global size: (dst_w, dst_h).
__kernel void pyramid_level(__global const float* src, uint src_offset, int src_w, int src_h, __global float* dst,
                            uint dst_offset, int dst_w, int dst_h, int span) {
  int i = get_global_id(0), j = get_global_id(1);
  if (i >= dst_w || j >= dst_h) return;
  float m = -INFINITY;
  for (int y = 2 * j; y <= min(2 * j + span, src_h - 1); ++y)
    for (int x = 2 * i; x <= min(2 * i + span, src_w - 1); ++x) m = fmax(m, src[src_offset + (uint)(y * src_w + x)]);
  dst[dst_offset + (uint)(j * dst_w + i)] = m;
}

// Level-of-detail march: HFVIS_PYRAMID_NEAR unit steps on the bilinear surface, then on
// level l = 1, 2, ... the steps t = NEAR * 2^(l-1) + q * 2^l, q = 1 .. NEAR/2, each reading
// the max texel of level l under the sample (a conservative height for the texel's square,
// placed at the sample's distance). `levels` holds (offset into pyramid, width, height, 0)
// per level; level 0 is not read from the pyramid. One direction per launch, arguments and
// global size as radius_march.
__kernel void pyramid_march(__global const float* heights, int width, int height, __global const float* pyramid,
                            __constant int4* levels, int level_count, float dir_x, float dir_y, float step_length,
                            float samples_per_unit, float ground_per_pixel, __global float* angles,
                            uint plane_offset) {
  int c = get_global_id(0), r = get_global_id(1);
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  const float h = heights[pixel];
  const float x0 = (float)cc, y0 = (float)rr;
  const float reach = tile_reach(dir_x, dir_y, width, height);
  float best_rise = 0.0f, best_t = 0.0f;
  const int near = min(HFVIS_PYRAMID_NEAR, (int)reach + 1);
  for (int n = 0; n < near; ++n) {
    float t = (float)(n + 1);
    float x = x0 + t * dir_x, y = y0 + t * dir_y;
    float rise = bl_bilinear(heights, width, height, x, y) - h;
    bl_keep_steepest(rise, t, bl_inside(x, y, width, height), &best_rise, &best_t);
    barrier(CLK_LOCAL_MEM_FENCE);  // one vectorised region per step (see radius_march)
  }
  // The levels the tile's longest ray reaches, then their samples in one flat loop; level
  // l's samples are q = 1 .. NEAR/2.
  int coarse_levels = 0;
  while (coarse_levels + 1 < level_count && (float)(HFVIS_PYRAMID_NEAR << coarse_levels) < reach) ++coarse_levels;
  const int per_level = HFVIS_PYRAMID_NEAR / 2;
  for (int n = 0; n < coarse_levels * per_level; ++n) {
    const int l = 1 + n / per_level, q = 1 + n % per_level;
    const int offset = levels[l].x, level_w = levels[l].y, level_h = levels[l].z;
    const float size = (float)(1 << l);
    float t = (float)(HFVIS_PYRAMID_NEAR << (l - 1)) + (float)q * size;
    float x = x0 + t * dir_x, y = y0 + t * dir_y;
    int tx = clamp((int)(fmax(x, 0.0f) / size), 0, level_w - 1);
    int ty = clamp((int)(fmax(y, 0.0f) / size), 0, level_h - 1);
    float rise = pyramid[offset + ty * level_w + tx] - h;
    bl_keep_steepest(rise, t, bl_inside(x, y, width, height), &best_rise, &best_t);
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  float elevation = bl_elevation(best_rise, best_t, ground_per_pixel);
  if (valid) angles[plane_offset + pixel] = elevation;
}

// Bandwidth floor: reads the height field and writes one value per pixel and direction,
// nothing else, so the report can say how close a method comes to the memory-bound limit
// of producing a K-plane result. The value depends on the direction so no write is hoisted.
// Each work-item owns 16 consecutive pixels of a row and moves them as one float16: explicit
// vectors, so the floor does not depend on PoCL's vectoriser.
// Global size: (ceil(W / 16), H), any local size.
__kernel void bandwidth_floor(__global const float* heights, int width, int height,
                              __global const SweepDirection* directions, int batch_size, __global float* angles) {
  int x = get_global_id(0) * 16, r = get_global_id(1);
  if (x >= width || r >= height) return;
  const uint at = (uint)(r * width + x);
  const uint plane = (uint)(width * height);
  if (x + 16 <= width) {
    const float16 h = vload16(0, heights + at);
    for (int b = 0; b < batch_size; ++b) vstore16(h * directions[b].dir_x, 0, angles + (uint)b * plane + at);
  } else {
    for (int b = 0; b < batch_size; ++b)
      for (int i = 0; i < width - x; ++i) angles[(uint)b * plane + at + i] = heights[at + i] * directions[b].dir_x;
  }
}
