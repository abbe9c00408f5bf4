// horizon.cl: horizons by the convex-hull-stack sweep (Timonen & Westerholm 2010,
// Algorithm 1) on lines through the pixel centres, reduced straight into the requested
// outputs, and the naive per-pixel ray march (the baseline and oracle).
//
// The sweep (horizon_lattice): a direction is a primitive integer step (a, b) in pixel
// axes. Every pixel centre lies on exactly one line of that direction, so every receiver is
// a sample of the line through its own centre, and the hull stack gives the horizon of the
// receiver's own ray from its own height. The line's samples between consecutive pixel
// centres (receivers) are where it crosses grid columns and rows, exact heights of the
// bilinear surface, and points between crossings; src/core/lattice_geometry.hpp builds the
// per-period table. Each receiver also takes the exact limit of its ray's elevation at
// t -> 0 (the surface's slope along the ray in its first cell): along a ray from a grid
// point the bilinear surface is a quadratic in the first cell, so (h(t) - h0) / t is linear
// there and its supremum is that limit or the first crossing, which is a sample.
//
// Heights arrive offset and z-scaled (h' = (h - base) * z_scale, base the field's heightBase, so
// h' may be negative) so that tilted planes at large offsets keep their precision; NaN = nodata.
//
// Compile-time parameters, besides those of sweep_framework.cl:
//   HFVIS_WANT_ANGLES, HFVIS_WANT_DISTANCES  write the direction's planes
//   HFVIS_WANT_SVF, HFVIS_WANT_AO            accumulate sky-view / ambient occlusion terms
//   HFVIS_WANT_ENV, HFVIS_ENV_CHANNELS       accumulate the irradiance from an environment's
//                                            tables (environment_light.cl), of 1 or 3 channels
//   HFVIS_CURVATURE                          lower every sample by the Earth's drop (argument
//                                            `drop`: c times the ground length of a unit of
//                                            position along the line or ray, squared: a pixel,
//                                            or a ground unit with HFVIS_ROW_SPACING;
//                                            docs/CONVENTIONS.md)
//   HFVIS_MAX_DISTANCE                       only samples within `window` pixels along the line
//                                            count (horizon_lattice: blocks and a backward
//                                            pass, below; horizon_naive: `max_steps`)
//   HFVIS_ROW_SPACING                        the ground spacing differs per row (latitude /
//                                            longitude grids): positions along a line are
//                                            whole units of ground length summed period by
//                                            period (along a ray ground lengths summed step by
//                                            step), from the per-row tables `row_length` and
//                                            `row_terms`
//   HFVIS_STRIPS                             horizon_lattice resumes lines part-way (a field in
//                                            strips of rows, see there)
//   HFVIS_ORIGIN                             the field was cut from a larger one (HeightField::
//                                            origin): horizon_lattice places positions along the
//                                            larger field's lines (receiver_index)
#include "shared/direction_terms.cl"
#include "environment_light.cl"
#include "shared/fast_math.cl"
#include "shared/sweep_framework.cl"
#include "shared/surface_normal.cl"

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
#ifndef HFVIS_WANT_ENV
#define HFVIS_WANT_ENV 0
#endif
#ifndef HFVIS_ENV_CHANNELS
#define HFVIS_ENV_CHANNELS 1
#endif
#ifndef HFVIS_CURVATURE
#define HFVIS_CURVATURE 0
#endif
#ifndef HFVIS_MAX_DISTANCE
#define HFVIS_MAX_DISTANCE 0
#endif
#ifndef HFVIS_ROW_SPACING
#define HFVIS_ROW_SPACING 0
#endif
#ifndef HFVIS_STRIPS
#define HFVIS_STRIPS 0
#endif
#ifndef HFVIS_ORIGIN
#define HFVIS_ORIGIN 0
#endif
#if HFVIS_ORIGIN && !HFVIS_ROW_SPACING && HFVIS_STRIPS && HFVIS_LANES != 1
#error "a strip's lines resume at indices of their own along a larger field's lines: one line per work-item"
#endif
#if HFVIS_MAX_DISTANCE && HFVIS_ROW_SPACING && HFVIS_LANES != 1
#error "a maximum distance with per-row spacing runs one line per work-item"
#endif
#if HFVIS_MAX_DISTANCE && HFVIS_STRIPS && HFVIS_LANES != 1
#error "a maximum distance in strips needs one line per work-item (a window's blocks are per line)"
#endif

// The normal at pixel (c, r) (surface_normal_sum, shared/surface_normal.cl) divided by its z:
// the normal is (x, y, 1) / |(x, y, 1)|, and (x, y) its slopes; (0, 0) when no quad is left.
// `heights` holds the field's rows from row0 on.
HFVIS_INLINE float2 surface_slopes(__global const float* heights, int width, int height, int row0, int c, int r,
                                   float h, float cell_x, float cell_y) {
  float sum[3];
  surface_normal_sum(heights, width, height, row0, c, r, h, cell_x, cell_y, sum);
  int any = sum[2] > 0.0f;
  return (float2)(any ? sum[0] / sum[2] : 0.0f, any ? sum[1] / sum[2] : 0.0f);
}

// Every pixel's normal as its slopes (surface_slopes), 8 bytes per pixel, for ambient
// occlusion. ambient_term is linear in the normal (its arctangent argument and its test
// are ratios), so the sweep passes (x, y, 1) and occlusion_scale divides the sum by
// |(x, y, 1)| once at the end. With HFVIS_ROW_SPACING each row takes its own cell sizes,
// row_cells[r] (else cell_x, cell_y). The normals of rows out_row0 .. out_row0 + rows - 1
// (a strip, see horizon_lattice), from heights that hold the field's rows from row0 on (the
// strip's and the rows around it). Global size: (W, rows) rounded up.
__kernel void pixel_normals(__global const float* heights, int width, int height, int row0, int out_row0,
                            int rows, float cell_x, float cell_y, __global const float2* row_cells,
                            __global float2* normals) {
  const int c = get_global_id(0), strip_row = get_global_id(1), r = out_row0 + strip_row;
  if (c >= width || strip_row >= rows) return;
#if HFVIS_ROW_SPACING
  const float2 cells = row_cells[r];
  cell_x = cells.x;
  cell_y = cells.y;
#endif
  normals[(uint)(strip_row * width + c)] =
      surface_slopes(heights, width, height, row0, c, r, heights[(r - row0) * width + c], cell_x, cell_y);
}

// The sums of normals (x, y, 1) made those of the unit normals: occlusion's, or `planes` planes
// of irradiance `stride` apart. Global size: pixels rounded up.
__kernel void occlusion_scale(__global const float2* normals, uint pixels, int planes, uint stride,
                              __global float* sums) {
  const uint p = get_global_id(0);
  if (p >= pixels) return;
  const float2 n = normals[p];
  const float length = sqrt(n.x * n.x + n.y * n.y + 1.0f);
  for (int i = 0; i < planes; ++i) sums[i * stride + p] = sums[i * stride + p] / length;
}

// Lanes (compile-time HFVIS_LANES): in the line-major (CPU) layout one work-item sweeps 8
// lines side by side, one per SIMD lane. A work-item's loop runs serially on one core and
// the hull stacks' pops are data-dependent branches; in lock step they become masked vector
// steps that end when no lane pops, with fewer mispredicted branches per sample. Measured
// on a 2-core AVX-512 CPU under PoCL (`hfvis svf -k 64`, 1024^2): 8 lanes 1.05 s of kernel
// time, 16 lanes 1.26 s, 4 lanes 1.45 s, one line per work-item 2.09 s. On GPUs
// (step-major layout) each work-item runs one line (HFVIS_LANES 1), so that neighbouring
// work-items read neighbouring stack entries.
#include "shared/lanes.cl"

HFVIS_DIRECTION_TERMS(float, int)
#if HFVIS_LANES > 1
HFVIS_DEFINE_ATAN(lane_float, lane_int)
HFVIS_DIRECTION_TERMS(lane_float, lane_int)
HFVIS_ENVIRONMENT_TERMS(lane_float, lane_int, convert_int8)
#endif

// A direction's outputs go to its planes, from `plane` on in `angles` / `distances`, and into
// the sums. Each launch runs one direction and every pixel is written by one work-item of it,
// so the read-modify-writes of the sums need no atomics. (cos_az, sin_az) is the direction on
// the ground at the receiver, weight its share of the circle of azimuth there and swath
// sin(pi weight) / pi (ambient_term). The environment's sums (HFVIS_WANT_ENV): direction's
// table at env_tables + env_offset of env_rows bands, channel c's sum at env_sum[c * env_stride].
#define HFVIS_ENV_PARAMS \
  , __global const float *env_tables, uint env_offset, int env_rows, __global float *env_sum, uint env_stride
#define HFVIS_ENV_ARGS , env_tables, env_offset, env_rows, env_sum, env_stride

// One receiver's outputs (the naive march).
HFVIS_INLINE void emit_direction(uint pixel, int nodata, int found, float rise, float run, float distance,
                                 float cos_az, float sin_az, float weight, float swath, uint plane,
                                 __global const float2* normals,
                                 __global float* angles, __global float* distances, __global float* svf_sum,
                                 __global float* ao_sum HFVIS_ENV_PARAMS) {
#if HFVIS_WANT_ANGLES
  angles[plane + pixel] = nodata ? NAN : elevation_term(found, rise, run);
#endif
#if HFVIS_WANT_DISTANCES
  distances[plane + pixel] = nodata ? NAN : distance;
#endif
#if HFVIS_WANT_SVF
  svf_sum[pixel] = nodata ? NAN : svf_sum[pixel] + weight * sky_term(found, rise, run);
#endif
#if HFVIS_WANT_AO
  const float2 n = normals[pixel];
  float term = ambient_term(found, rise, run, n.x, n.y, 1.0f, cos_az, sin_az, weight, swath);
  ao_sum[pixel] = nodata ? NAN : ao_sum[pixel] + term;
#endif
#if HFVIS_WANT_ENV
  const float2 m = normals[pixel];
  const float x = lower_limit(found, rise, run, m.x * cos_az + m.y * sin_az, 1.0f);
  environment_add(env_sum + pixel, env_stride, HFVIS_ENV_CHANNELS, nodata, x, m.x, m.y, 1.0f, cos_az, sin_az,
                  env_tables + env_offset, env_rows);
#endif
}

// The outputs of a lane vector of receivers (the sweep): the terms lane-parallel, the
// stores lane by lane where `live`.
HFVIS_INLINE void emit_lanes(lane_int live, lane_int pixel, lane_int nodata, lane_int found, lane_float rise,
                             lane_float run, lane_float distance, lane_float cos_az, lane_float sin_az,
                             lane_float weight, lane_float swath, uint plane,
                             __global const float2* normals, __global float* angles,
                             __global float* distances, __global float* svf_sum,
                             __global float* ao_sum HFVIS_ENV_PARAMS) {
#if HFVIS_WANT_ANGLES
  const lane_float elevation = select(elevation_term(found, rise, run), (lane_float)NAN, nodata);
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l)
    if (ILANE(live, l)) angles[plane + (uint)ILANE(pixel, l)] = LANE(elevation, l);
#endif
#if HFVIS_WANT_DISTANCES
  const lane_float dist = select(distance, (lane_float)NAN, nodata);
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l)
    if (ILANE(live, l)) distances[plane + (uint)ILANE(pixel, l)] = LANE(dist, l);
#endif
#if HFVIS_WANT_SVF
  const lane_float sky = weight * sky_term(found, rise, run);
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    const uint p = (uint)ILANE(pixel, l);
    if (ILANE(live, l)) svf_sum[p] = ILANE(nodata, l) ? NAN : svf_sum[p] + LANE(sky, l);
  }
#endif
#if HFVIS_WANT_AO || HFVIS_WANT_ENV
  lane_float nx, ny;
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    const float2 n = normals[ILANE(live, l) ? (uint)ILANE(pixel, l) : 0u];
    LANE(nx, l) = n.x;
    LANE(ny, l) = n.y;
  }
#endif
#if HFVIS_WANT_AO
  const lane_float term =
      ambient_term(found, rise, run, nx, ny, (lane_float)1.0f, cos_az, sin_az, weight, swath);
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    const uint p = (uint)ILANE(pixel, l);
    if (ILANE(live, l)) ao_sum[p] = ILANE(nodata, l) ? NAN : ao_sum[p] + LANE(term, l);
  }
#endif
#if HFVIS_WANT_ENV
  // The terms lane-parallel (the arctangent above all), the tables' gathers lane by lane.
  const lane_float x = lower_limit(found, rise, run, nx * cos_az + ny * sin_az, (lane_float)1.0f);
  lane_int band;
  lane_float q1, q2, toward, across;
  environment_terms(x, nx, ny, cos_az, sin_az, env_rows, &band, &q1, &q2, &toward, &across);
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l)
    if (ILANE(live, l))
      environment_accumulate(env_sum + (uint)ILANE(pixel, l), env_stride, HFVIS_ENV_CHANNELS, ILANE(nodata, l) != 0,
                             ILANE(band, l), LANE(q1, l), LANE(q2, l), 1.0f, LANE(toward, l), LANE(across, l),
                             env_tables + env_offset);
#endif
}

// The exact limit of the receivers' elevation slope at t -> 0 along (a, b): the bilinear
// surface's directional derivative into the first cell, from each receiver's height h and
// its neighbours along the two axes, as a rise over the period |(a, b)| (the caller's run).
// NaN where the ray leaves the field at once or the first cell (off the axes; on an axis, the
// first edge) has a nodata corner: it has no surface there (the diagonal corner's weight
// vanishes at the receiver, but a nodata one takes the whole cell's surface). Lanes not
// `live` read the buffer's first height. `heights` holds the field's rows from row0 on.
HFVIS_INLINE lane_float near_rise(__global const float* heights, int width, int height, int row0, lane_int live,
                                  lane_int c, lane_int r, lane_float h, int a, int b) {
  const int sx = a > 0 ? 1 : (a < 0 ? -1 : 0), sy = b > 0 ? 1 : (b < 0 ? -1 : 0);
  const lane_int leaves = (c + sx < 0) | (c + sx >= width) | (r + sy < 0) | (r + sy >= height);
  const lane_int x_at = select((lane_int)0, (r - row0) * width + clamp(c + sx, 0, width - 1), live);
  const lane_int y_at = select((lane_int)0, (clamp(r + sy, 0, height - 1) - row0) * width + c, live);
  lane_float hx, hy;
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    LANE(hx, l) = heights[ILANE(x_at, l)];
    LANE(hy, l) = heights[ILANE(y_at, l)];
  }
  const lane_float rise = (hx - h) * (float)abs(a) + (hy - h) * (float)abs(b);
#if HFVIS_HAS_NODATA
  // (on an axis the diagonal corner is hx or hy itself)
  const lane_int d_at = select((lane_int)0, x_at + (y_at - (r - row0) * width - c), live);
  lane_float hd;
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) LANE(hd, l) = heights[ILANE(d_at, l)];
  return select(rise, (lane_float)NAN, leaves | isnan(hd));
#else
  return select(rise, (lane_float)NAN, leaves);
#endif
}

// The height of lattice sample s for the lanes' period receivers at (c, r): `ok` are the lanes
// that take it (live, and inside the field where `edge`: only the first period of a line can
// reach outside it); *valid: those with a height. A crossing (or the receiver) also gives the
// heights of the corners it lies between, at (ox, oy) and (ox + ex, oy + ey), in *corner0 and
// *corner1 (the segment peaks reuse them); a sample inside a cell leaves them as they are. Lanes without the sample read the buffer's
// first height alone (their cell may lie outside the field). `heights` holds the field's rows
// from row0 on.
HFVIS_INLINE lane_float lane_sample_height(__global const float* heights, int width, int height, int row0,
                                           __global const LatticeSample* s, lane_int c, lane_int r, lane_int ok,
                                           int edge, lane_int* valid, lane_float* corner0, lane_float* corner1) {
  const int ex = s->ex, ey = s->ey;
  const float w00 = s->w00, w10 = s->w10, w01 = s->w01, w11 = s->w11;
  const lane_int x0 = c + s->ox, y0 = r + s->oy;
  if (edge) ok = ok & (x0 >= 0) & (x0 + ex <= width - 1) & (y0 >= 0) & (y0 + ey <= height - 1);
  const lane_int at = select((lane_int)0, (y0 - row0) * width + x0, ok);
  const lane_int right = select((lane_int)0, (lane_int)ex, ok);
  const lane_int down = select((lane_int)0, (lane_int)(ey * width), ok);
  lane_float h;
  if (ex + ey < 2) {
    // A crossing or the receiver: at most two corners of positive weight, and the
    // zero-weight terms of the four-corner sum add nothing.
    const lane_int at_next = at + right + down;
    lane_float h0, h1;
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l) {
      LANE(h0, l) = heights[ILANE(at, l)];
      LANE(h1, l) = heights[ILANE(at_next, l)];
    }
    // The receiver (ex = ey = 0, weight 1) is its pixel's height as it is (1 h + 0 h would
    // turn an infinite height into NaN).
    h = ex + ey == 0 ? h0 : h0 + (ex ? w10 : w01) * (h1 - h0);
    *corner0 = h0;
    *corner1 = h1;
#if HFVIS_HAS_NODATA
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l) {
      if (isnan(LANE(h, l)))
        LANE(h, l) = lattice_height(heights, (uint)ILANE(at, l), (uint)ILANE(right, l), (uint)ILANE(down, l), w00,
                                    w10, w01, w11);
    }
#endif
  } else {
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l)
      LANE(h, l) = lattice_height(heights, (uint)ILANE(at, l), (uint)ILANE(right, l), (uint)ILANE(down, l), w00,
                                  w10, w01, w11);
  }
#if HFVIS_HAS_NODATA
  *valid = ok & !isnan(h);
#else
  *valid = ok;
#endif
  return h;
}

// The piece of a line between two consecutive samples (src/core/lattice_geometry.hpp, struct
// CellSegment): thirteen 4-byte members, read field by field.
typedef struct {
  float tau_far, tau_near;  // its ends, pixels from the period's receiver toward +(a, b)
  int ox, oy;               // its cell's lower corner, relative to the receiver
  float fx, fy, dx, dy;     // cell fractions at the far end, and their change to the near end
  int curved;               // off the grid lines: the surface along it is a quadratic
  // Where the cell's corners (00, 10, 01, 11) were read already: 0 and 1 the far end's two
  // corners, 2 and 3 the near end's (lane_sample_height's corner0 and corner1), 4 nowhere.
  int from00, from10, from01, from11;
} CellSegment;

// The maximum of the bilinear surface inside segment g of the lanes' period receivers at
// (c, r), where it lies strictly inside the segment: *valid there (for lanes `ok`, inside the
// field where `edge`, with four finite corners), its tau in *tau and its height returned. The
// caller also requires its position to fall strictly between those of the segment's ends (as
// the sweep rounds them), so that positions grow strictly along the sweep. Along
// the segment, at u in [0, 1] from the far end, the cell fractions are (fx + u dx, fy + u dy)
// and the surface h00 + gx x + gy y + e x y (e the cell's twist) is A + B u + C u^2 with
// C = e dx dy: it peaks inside where C < 0 and 0 < -B / 2C < 1, at height A + B u / 2. A
// convex or flat piece (C >= 0) has its maximum at an end, which is a sample already. Lanes
// without the segment read the buffer's first height alone.
//
// far0, far1, near0, near1 are the corners the segment's ends read (the far end's corner0 and
// corner1, the near end's); where `reuse`, the corners g names there are taken from them, the
// others read (where the far end was not read in this launch, all four are read).
HFVIS_INLINE lane_float segment_corner(__global const float* heights, int from, int reuse, lane_float far0,
                                       lane_float far1, lane_float near0, lane_float near1, lane_int at) {
  // (Named values, not an array: an array indexed at run time would live in memory.)
  if (reuse && from < 4) return from == 0 ? far0 : from == 1 ? far1 : from == 2 ? near0 : near1;
  lane_float h;
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) LANE(h, l) = heights[ILANE(at, l)];
  return h;
}

// The quadratic along segment g (segment_peak): its far end's corner and slopes, the cell's
// twist, B and C, and the lanes where it peaks strictly inside (candidate; NaN corners fail the
// comparisons, infinite ones isfinite(A) in segment_peak_height).
typedef struct {
  lane_float h00, gx, gy, e, B, C;
  lane_int candidate;
} SegmentQuadratic;

HFVIS_INLINE SegmentQuadratic segment_quadratic(__global const float* heights, int width, int height, int row0,
                                                __global const CellSegment* g, lane_int c, lane_int r, lane_int ok,
                                                int edge, int reuse, lane_float far0, lane_float far1,
                                                lane_float near0, lane_float near1, int at_receiver) {
  const lane_int x0 = c + g->ox, y0 = r + g->oy;
  if (edge) ok = ok & (x0 >= 0) & (x0 + 1 <= width - 1) & (y0 >= 0) & (y0 + 1 <= height - 1);
  const int from00 = g->from00, from10 = g->from10, from01 = g->from01, from11 = g->from11;
  lane_float h00, h10, h01, h11;
  if (reuse && (from00 | from10 | from01 | from11) < 4) {  // every corner read already (no code has bit 2 but 4)
    h00 = from00 == 0 ? far0 : from00 == 1 ? far1 : from00 == 2 ? near0 : near1;
    h10 = from10 == 0 ? far0 : from10 == 1 ? far1 : from10 == 2 ? near0 : near1;
    h01 = from01 == 0 ? far0 : from01 == 1 ? far1 : from01 == 2 ? near0 : near1;
    h11 = from11 == 0 ? far0 : from11 == 1 ? far1 : from11 == 2 ? near0 : near1;
  } else {
    const lane_int at = select((lane_int)0, (y0 - row0) * width + x0, ok);
    const lane_int right = select((lane_int)0, (lane_int)1, ok), down = select((lane_int)0, (lane_int)width, ok);
    h00 = segment_corner(heights, from00, reuse, far0, far1, near0, near1, at);
    h10 = segment_corner(heights, from10, reuse, far0, far1, near0, near1, at + right);
    h01 = segment_corner(heights, from01, reuse, far0, far1, near0, near1, at + down);
    h11 = segment_corner(heights, from11, reuse, far0, far1, near0, near1, at + down + right);
  }
  const float fx = g->fx, fy = g->fy, dx = g->dx, dy = g->dy;
  SegmentQuadratic w;
  w.h00 = h00;
  w.gx = h10 - h00;
  w.gy = h01 - h00;
  w.e = (h11 - h01) - w.gx;
  w.B = w.gx * dx + w.gy * dy + w.e * (fx * dy + fy * dx);
  w.C = w.e * (dx * dy);
  // (`at_receiver`: the segment ends at its period's receiver, where a peak within a thousandth of
  // the segment of it is left to the receiver's own slope limit: within rounding of the receiver,
  // at S > 1, it stood a rounding above it at a distance of 1e-7, a horizon of 88 degrees on a
  // wall top; the limit differs from such a peak's slope by about the thousandth)
  w.candidate = ok & (w.C < 0.0f) & (w.B > 0.0f) & (w.B < (at_receiver ? -1.998f : -2.0f) * w.C);
  return w;
}

// The peak of a candidate: its tau in *tau, its height returned; *valid: the candidates whose
// four corners are finite (A, the far end's height, is finite only where all four are).
HFVIS_INLINE lane_float segment_peak_height(__global const CellSegment* g, SegmentQuadratic w, lane_float* tau,
                                            lane_int* valid) {
  const float fx = g->fx, fy = g->fy, tau_far = g->tau_far, tau_near = g->tau_near;
  const lane_float A = w.h00 + w.gx * fx + w.gy * fy + w.e * (fx * fy);
  const lane_float u = w.B / (-2.0f * w.C);
  *tau = tau_far - u * (tau_far - tau_near);
  *valid = w.candidate & isfinite(A);
  return A + 0.5f * w.B * u;
}

HFVIS_INLINE lane_float segment_peak(__global const float* heights, int width, int height, int row0,
                                     __global const CellSegment* g, lane_int c, lane_int r, lane_int ok, int edge,
                                     int reuse, lane_float far0, lane_float far1, lane_float near0,
                                     lane_float near1, int at_receiver, lane_float* tau, lane_int* valid) {
  const SegmentQuadratic w = segment_quadratic(heights, width, height, row0, g, c, r, ok, edge, reuse, far0, far1,
                                               near0, near1, at_receiver);
  return segment_peak_height(g, w, tau, valid);
}

// One step of Algorithm 1 (Timonen & Westerholm 2010) on the lanes' hull stacks, in two halves:
// hull_pop finds the sample's occluder, hull_push then pushes the sample (horizon_lattice puts
// a segment's peak between the two). The sample (hs, here) arrives beyond every entry, on the
// side `toward` (+1: positions grow, the forward sweep; -1: they shrink, the backward pass of
// a window). Pop while the entry below the top casts at least as steep a slope on the sample
// as the top (so the farther wins ties); (rise, run) become the remaining top's rise above the
// sample and its distance (run 0: no entry) where `valid`. Entry k of a lane's stack is at
// stacks[stack + k entry]; the top two entries are in registers as well (below: valid where
// n >= 2). A step that pops nothing (the common case: a peak's push, a sample on a rising
// slope) reads no entry; each pop loads the next entry down.
HFVIS_INLINE void hull_pop(__global float2* stacks, lane_int stack, int entry, lane_int valid, lane_float hs,
                           lane_float here, float toward, lane_int* n, lane_float* top_h, lane_float* top_p,
                           lane_float* below_h, lane_float* below_p, lane_float* rise, lane_float* run) {
  lane_float v1h = *top_h - hs, v1d = toward * (here - *top_p), v2h = *below_h - hs,
             v2d = toward * (here - *below_p);
  lane_int pop = valid & (*n > 1) & (v2h * v1d >= v1h * v2d);
  lane_int deeper = stack + (*n - 3) * entry;  // entry n - 3, below `below`
  while (ANY_LANE(pop)) {
    lane_float next_h, next_p;
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l) {
      const int k = max(ILANE(deeper, l), ILANE(stack, l));
      const float2 e = stacks[k];
      LANE(next_h, l) = e.x;
      LANE(next_p, l) = e.y;
    }
    v1h = select(v1h, v2h, pop);
    v1d = select(v1d, v2d, pop);
    *top_h = select(*top_h, *below_h, pop);
    *top_p = select(*top_p, *below_p, pop);
    *below_h = select(*below_h, next_h, pop);
    *below_p = select(*below_p, next_p, pop);
    v2h = *below_h - hs;
    v2d = toward * (here - *below_p);
    *n = select(*n, *n - 1, pop);
    pop = pop & (*n > 1) & (v2h * v1d >= v1h * v2d);
    deeper -= entry;
  }
  *rise = select(*rise, v1h, valid);
  *run = select(*run, select((lane_float)0.0f, v1d, *n > 0), valid);  // 0: no occluder
}

HFVIS_INLINE void hull_push(__global float2* stacks, lane_int stack, int entry, lane_int valid, lane_float hs,
                            lane_float here, lane_int* n, lane_float* top_h, lane_float* top_p,
                            lane_float* below_h, lane_float* below_p) {
  const lane_int push = stack + *n * entry;
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    if (ILANE(valid, l)) stacks[ILANE(push, l)] = (float2)(LANE(hs, l), LANE(here, l));
  }
  *below_h = select(*below_h, *top_h, valid);
  *below_p = select(*below_p, *top_p, valid);
  *top_h = select(*top_h, hs, valid);
  *top_p = select(*top_p, here, valid);
  *n = select(*n, *n + 1, valid);
}

HFVIS_INLINE void hull_step(__global float2* stacks, lane_int stack, int entry, lane_int valid, lane_float hs,
                            lane_float here, float toward, lane_int* n, lane_float* top_h, lane_float* top_p,
                            lane_float* below_h, lane_float* below_p, lane_float* rise, lane_float* run) {
  hull_pop(stacks, stack, entry, valid, hs, here, toward, n, top_h, top_p, below_h, below_p, rise, run);
  hull_push(stacks, stack, entry, valid, hs, here, n, top_h, top_p, below_h, below_p);
}

// The sample's height as the stack holds it: lowered by the Earth's drop (see horizon_lattice).
#if HFVIS_CURVATURE
#define HFVIS_STACK_HEIGHT(h, here) ((h) - drop * (here) * (here))
#else
#define HFVIS_STACK_HEIGHT(h, here) (h)
#endif

// The index of receiver (c, r) of the field along its line of step (a, b) through the larger field
// it was cut from, whose pixel (c, r) is this field's (c - origin_col, r - origin_row) (without an
// origin, the field itself): the receivers beyond it along +(a, b). As receiverIndex
// (src/core/lattice_geometry.cpp) computes it.
HFVIS_INLINE int receiver_index(int c, int r, int a, int b, int whole_width, int whole_height) {
  int m = INT_MAX;
  if (a > 0) m = min(m, (whole_width - 1 - c) / a);
  if (a < 0) m = min(m, c / -a);
  if (b > 0) m = min(m, (whole_height - 1 - r) / b);
  if (b < 0) m = min(m, r / -b);
  return m;
}

#if HFVIS_ROW_SPACING
// The position of receiver (c, r), the first of its line in this field, along the line through
// the larger field (HFVIS_ORIGIN; without one 0: a line starts at its far end), in units: the m
// periods (receiver_index) from it to that line's far end, row_length[r] units each along a row
// (b = 0), else row_beyond[R] - row_beyond[R + m b] (rows R of the larger field; modulo 2^32,
// the difference below 2^24). Integers, exact, as lineStartPosition (src/core/horizon_common.cpp)
// computes them.
HFVIS_INLINE float line_start_position(int c, int r, int a, int b, int origin_col, int origin_row, int whole_width,
                                       int whole_height, __global const float* row_length,
                                       __global const uint* row_beyond) {
#if HFVIS_ORIGIN
  const int m = receiver_index(c + origin_col, r + origin_row, a, b, whole_width, whole_height);
  if (b == 0) return (float)(m * (int)row_length[r]);
  const int R = r + origin_row;
  return (float)(row_beyond[R] - row_beyond[R + m * b]);
#else
  return 0.0f;
#endif
}
#endif

#if HFVIS_MAX_DISTANCE

#if HFVIS_STRIPS
// The block of the sample `tau` before receiver `index` of a line, computed as horizon_lattice's
// loop computes it (position and difference in statements of their own: no fused multiply-add).
HFVIS_INLINE int block_of(int index, float tau, float period, float inv_window) {
  const float base = (float)index * period;
  const float here = base - tau;
  return (int)floor(here * inv_window);
}
#if HFVIS_ROW_SPACING
// The same with per-row spacing, for sample `tau` of period j (j <= 0) of a line resumed at its
// receiver 0 in row r, column c: receiver -1's position is `base` (carried), receiver 0's base
// plus its period, earlier ones' in receiver_base (rows from row0 on), as the loop sums them.
HFVIS_INLINE int block_of_row(int j, float tau, int c, int r, int a, int b, float base, int row0, int width,
                              float inv_period, float inv_window, __global const float* row_length,
                              __global const float* receiver_base) {
  const int row = r - j * b;
  const float position = j == 0    ? base + row_length[row]
                         : j == -1 ? base
                                   : receiver_base[(row - row0) * width + (c - j * a)];
  const float tau_scale = row_length[row] * inv_period;
  const float here = position - tau * tau_scale;
  return (int)floor(here * inv_window);
}
#endif
#endif

// Horizons within a window of `window` pixels along the line (HFVIS_MAX_DISTANCE; units of
// ground length, and positions in them, with HFVIS_ROW_SPACING, one line per work-item). The
// line's positions are cut into blocks of the window's length (block = floor(position / window));
// a receiver's window then lies in its own block and the one before. The forward sweep
// restarts its stack at every block, so it gives the steepest sample of the receiver's own
// block (all nearer than the window). This pass gives the rest, the steepest sample of the
// block before within the window: on entering block k (at sample q of period i), it walks
// block k's receivers nearest-first and the samples of block k - 1 backwards from the
// nearest, pushing each sample once it is within the window of the current receiver (the
// set grows at its far end, so Algorithm 1 runs backwards: hull_step toward -1); that hull's
// tangent from the receiver is found by binary search (the slopes from a point beyond an upper
// hull rise and then fall along it; ties go to the farther entry). Writes (rise, run) per
// receiver pixel into window_far (run 0: none), which the forward sweep combines. Every sample
// is pushed twice and each receiver searches once: O(n log m) for m hull entries. The cut is
// decided in float arithmetic: by block membership (position * inv_window) in the forward
// sweep and by x - here <= window here, so a sample within rounding of the window's length
// (relative 1e-7) may go either way.
HFVIS_INLINE void window_pass(__global const float* heights, int width, int height, int row0, int out_row0,
                              __global const LatticeSample* samples, __global const CellSegment* segments,
                              int n_samples, int a, int b, float period,
                              float window, float inv_window, float drop, lane_int c, lane_int r,
                              lane_int receivers, lane_int stack, int entry, int i, int q, int k, int trips,
                              int offset, int shift, float base, float inv_period, __global const float* row_length,
                              __global float* receiver_base, __global float2* stacks,
                              __global float2* window_far) {
  // Periods are counted from the launch's first receiver, `offset` along the whole line (a
  // strip's part of a line; 0 otherwise); receivers before it (j < 0) are another launch's.
  // Positions count `shift` receivers more (HFVIS_ORIGIN: those of the larger field's line beyond
  // this field; 0 otherwise).
  int end = max(i, 0);  // block k's receivers here are periods max(i, 0) .. end - 1
#if HFVIS_ROW_SPACING
  // Positions are whole units of ground length, summed along the line (one line per work-item):
  // receiver j's is receiver_base[its pixel] (rows from row0 on, as the heights; in strips those of earlier
  // strips come from the host), which the forward sweep stores as it reaches it. `base` is
  // receiver i's, or for i < 0 (a strip resumed inside a block) receiver -1's. Block k's
  // receivers are not reached yet: their positions are summed on here as the forward sweep
  // will sum them, and stored.
  float x = i >= 0 ? base : base + row_length[r + i * b];  // receiver max(i, 0)'s
  for (; end < trips; ++end) {
    const int er = r - (end - i) * b;
    if (end > max(i, 0)) x = x + row_length[er];
    if ((int)floor(x * inv_window) != k) break;
    receiver_base[(er - row0) * width + (c - (end - i) * a)] = x;
  }
#else
  while (end < trips && (int)floor((float)(offset + shift + end) * period * inv_window) == k) ++end;
#endif
  int ci = q > 0 ? i : i - 1, cq = q > 0 ? q - 1 : n_samples - 1;  // the nearest sample before (i, q)
  // Backwards, the peak inside the segment from sample (ci, cq) to the one after it comes just
  // before (ci, cq): it is taken with it, once (ci, cq) is within the window and in block k - 1,
  // and where it lies in block k - 1 itself (as the forward sweep takes it); or before, where
  // (ci, cq) lies beyond the window's far end (or the block's) and the peak within it: the
  // segment straddles the end (a peak at 3.5 pixels within a window of 4.1 was dropped, its
  // segment's far end at 4.2). `taken`: the lanes whose peak before (ci, cq) is on the stack.
  lane_int n = 0, taken = 0;
  lane_float top_h = 0.0f, top_p = 0.0f, below_h = 0.0f, below_p = 0.0f, rise = 0.0f, run = 0.0f;
  for (int j = end - 1; j >= max(i, 0); --j) {
#if HFVIS_ROW_SPACING
    const float x = receiver_base[(r - (j - i) * b - row0) * width + (c - (j - i) * a)];
#else
    const float x = (float)(offset + shift + j) * period;
#endif
    while (offset + ci >= 0) {
      __global const LatticeSample* s = samples + cq;
#if HFVIS_ROW_SPACING
      // As the forward sweep computes a sample's position.
      const int sr = r - (ci - i) * b;
      const float sample_base = receiver_base[(sr - row0) * width + (c - (ci - i) * a)];
      const float tau_scale = row_length[sr] * inv_period;
      const float here = sample_base - s->tau * tau_scale;
#else
      const float here = (float)(offset + shift + ci) * period - s->tau;
#endif
      const int reached = (int)floor(here * inv_window) == k - 1 && x - here <= window;
      const int gq = cq + 1 < n_samples ? cq + 1 : 0, gi = cq + 1 < n_samples ? ci : ci + 1;
      __global const CellSegment* g = segments + gq;
      if (g->curved) {
#if HFVIS_ROW_SPACING
        const int gr = r - (gi - i) * b;
        const float segment_base = receiver_base[(gr - row0) * width + (c - (gi - i) * a)];
        const float segment_scale = row_length[gr] * inv_period;
#else
        const float segment_base = (float)(offset + shift + gi) * period, segment_scale = 1.0f;
#endif
        const float here_near = segment_base - samples[gq].tau * segment_scale;
        lane_int valid;
        lane_float tau_peak;
        const lane_float h_peak = segment_peak(heights, width, height, row0, g, c - (gi - i) * a, r - (gi - i) * b,
                                               gi < receivers, offset + gi == 0, 0, 0.0f, 0.0f, 0.0f, 0.0f,
                                               gq == n_samples - 1, &tau_peak, &valid);
        const lane_float here_peak = segment_base - tau_peak * segment_scale;
        valid = valid & !taken & (here_peak > here) & (here_peak < here_near) &
                (LANE_INT(floor(here_peak * inv_window)) == k - 1);
        if (!reached) valid = valid & (x - here_peak <= window);
        if (ANY_LANE(valid))
          hull_step(stacks, stack, entry, valid, HFVIS_STACK_HEIGHT(h_peak, here_peak), here_peak, -1.0f, &n,
                    &top_h, &top_p, &below_h, &below_p, &rise, &run);
        taken = taken | valid;
      }
      if (!reached) break;
      lane_int valid;
      lane_float unused0, unused1;
      const lane_float h = lane_sample_height(heights, width, height, row0, s, c - (ci - i) * a, r - (ci - i) * b,
                                              ci < receivers, offset + ci == 0, &valid, &unused0, &unused1);
      hull_step(stacks, stack, entry, valid, HFVIS_STACK_HEIGHT(h, here), (lane_float)here, -1.0f, &n, &top_h,
                &top_p, &below_h, &below_p, &rise, &run);
      if (--cq < 0) cq = n_samples - 1, --ci;
      taken = 0;
    }
    // The tangent from receiver j: the peak of the slopes along the stack (entry 0 nearest).
    const lane_int live = j < receivers;
    const lane_int jr = r - (j - i) * b, jc = c - (j - i) * a;
    const lane_int at = select((lane_int)0, (jr - row0) * width + jc, live);
    const lane_int pixel = select((lane_int)0, (jr - out_row0) * width + jc, live);
    lane_float hx;
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l) LANE(hx, l) = heights[ILANE(at, l)];
    const lane_float hs = HFVIS_STACK_HEIGHT(hx, x);
    lane_int lo = 0, hi = n - 1;
    lane_int searching = live & (lo < hi);
    while (ANY_LANE(searching)) {
      const lane_int mid = (lo + hi) >> 1;
      lane_float h0, p0, h1, p1;
#pragma unroll
      for (int l = 0; l < HFVIS_LANES; ++l) {
        const int at = ILANE(stack, l) + (ILANE(searching, l) ? ILANE(mid, l) * entry : 0);
        const float2 e0 = stacks[at], e1 = stacks[at + (ILANE(searching, l) ? entry : 0)];
        LANE(h0, l) = e0.x;
        LANE(p0, l) = e0.y;
        LANE(h1, l) = e1.x;
        LANE(p1, l) = e1.y;
      }
      const lane_int up = (h1 - hs) * (x - p0) >= (h0 - hs) * (x - p1);
      lo = select(lo, mid + 1, searching & up);
      hi = select(hi, mid, searching & !up);
      searching = searching & (lo < hi);
    }
    lane_float far_h, far_p;
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l) {
      const float2 e = stacks[ILANE(stack, l) + (ILANE(n, l) > 0 ? ILANE(lo, l) * entry : 0)];
      LANE(far_h, l) = e.x;
      LANE(far_p, l) = e.y;
    }
    const lane_float far_rise = far_h - hs, far_run = select((lane_float)0.0f, x - far_p, n > 0);
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l)
      if (ILANE(live, l)) window_far[ILANE(pixel, l)] = (float2)(LANE(far_rise, l), LANE(far_run, l));
  }
}
#endif

// The sweep of one direction (a, b): lines j = lanes * work-item + lane, each from its far
// end toward -(a, b), in lock step (a lane whose line has ended is masked). Line j of this
// launch is lines[j] = (col, row, receivers, stack): its first receiver here at (col, row),
// its t-th at (col - t a, row - t b), for t < receivers. Per receiver, the period's samples
// farther along the line come first (samples[0 .. n_samples - 2], farthest first), then the
// receiver itself (the last sample: tau 0, weight 1 on its own pixel). Each sample is one step
// of Algorithm 1 (hull_step); the top that remains before the push is its horizon occluder.
// Samples outside the field or without height are absent. Stack entry k of a line is (height,
// position along the line in pixels from its far end) at stacks[line.w + k stride]; the
// capacity is every sample of its periods here plus the entries it arrives with.
// period_ground = period * ground_per_pixel, the ground length of a period.
//
// Strips (a field beyond the device's memory, src/ops/horizon.cpp): `heights` holds the field's rows
// from row0 on and the outputs (normals, planes, sums, window_far, receiver_base) its rows from
// out_row0 on. With HFVIS_STRIPS, line j resumes its whole line's sweep: line_state[j] = (index of
// its first receiver here along the whole line, entries of the stack it arrives with, their offset
// in carry_in, the receivers' position before it as float bits (HFVIS_ROW_SPACING)); the
// kernel copies those entries into its stack, and on leaving writes the stack's size into .y and
// the position into .w (carry_stacks then moves the stacks on). Without, every line starts
// at its far end with an empty stack and line_state and carry_in are not used.
//
// With HFVIS_ORIGIN the field was cut from a larger one of whole_width x whole_height pixels, its
// pixel (0, 0) at (origin_col, origin_row) there: positions (and so a window's blocks) count from
// the far end of the larger field's line (receiver_index), so that every sample lies where it lies
// in the larger field's sweep, to the bit; a line still starts at this field's edge with an empty
// stack. Lanes share their positions: the host gives a work-item's lanes lines that start at the
// same index there (lane 0's is taken for all). With HFVIS_ROW_SPACING each lane's line starts at
// its own position there instead (line_start_position, from row_beyond).
//
// With HFVIS_MAX_DISTANCE only samples within `window` (pixels along the line; units with
// HFVIS_ROW_SPACING) count, inv_window = 1 / window (window_pass; window_far: one (rise,
// run) per pixel; in strips one line per work-item; with HFVIS_ROW_SPACING one line per
// work-item on the whole field, receiver_base the receivers' positions). With
// HFVIS_ROW_SPACING positions are whole units of ground length (sweepUnit), ground_per_pixel
// that unit's ground length: row_length[r] is the units of the period from a receiver in row r
// to the next one along +(a, b) (a whole number), row_terms[r] that period's unit ground
// direction (x, y), weight and swath (they replace cos_azimuth, sin_azimuth, weight and swath),
// row_beyond where a line starts (line_start_position), and drop is per unit squared
// (period_ground is unused). Preconditions: lines of this launch only; stride 1 (line-major) or
// the launch's line count (step-major). Global size: ceil(n_lines / HFVIS_LANES) rounded up to the local size.
__kernel void horizon_lattice(__global const float* heights, int width, int height, int row0, int out_row0,
                              __global const int4* lines, int n_lines, __global const LatticeSample* samples,
                              __global const CellSegment* segments, int n_samples, int a, int b, float period, float ground_per_pixel,
                              float period_ground, float drop, float window, float inv_window,
                              int origin_col, int origin_row, int whole_width, int whole_height,
                              __global const float* row_length, __global const float4* row_terms,
                              __global const uint* row_beyond, float cos_azimuth,
                              float sin_azimuth, float weight, float swath, uint plane, __global float2* stacks,
                              uint stride, __global int4* line_state, __global const float2* carry_in,
                              __global float2* window_far, __global float* receiver_base,
                              __global const float2* normals,
                              __global float* angles, __global float* distances, __global float* svf_sum,
                              __global float* ao_sum HFVIS_ENV_PARAMS) {
  const int first = get_global_id(0) * HFVIS_LANES;
  if (first >= n_lines) return;
#if !HFVIS_STRIPS
  row0 = out_row0 = 0;  // the whole field: constants, folded into the indexing
#endif
  const int entry = (int)stride;  // between a line's consecutive stack entries
  lane_int c, r, receivers, stack;
  lane_int start = 0;             // the first receiver's index along the whole line
  lane_int n = 0;                 // stack sizes
  lane_float top_h = 0.0f, top_p = 0.0f, below_h = 0.0f, below_p = 0.0f, rise = 0.0f, run = 0.0f;
#if HFVIS_ROW_SPACING
  const float inv_period = 1.0f / period;
  lane_float base = 0.0f;  // the receivers' position along their lines, in units
#else
  const float inv_period = 0.0f;  // (window_pass takes it with per-row spacing only)
#endif
  int trips = 0;  // the longest line's receivers
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    const int4 line = lines[min(first + l, n_lines - 1)];
    ILANE(c, l) = line.x;
    ILANE(r, l) = line.y;
    ILANE(receivers, l) = first + l < n_lines ? line.z : 0;
    ILANE(stack, l) = line.w;
    trips = max(trips, ILANE(receivers, l));
  }
#if HFVIS_STRIPS
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    if (first + l < n_lines) {
      const int4 state = line_state[first + l];
      const int depth = state.y;
      for (int k = 0; k < depth; ++k) stacks[ILANE(stack, l) + k * entry] = carry_in[state.z + k];
      const float2 top = depth > 0 ? carry_in[state.z + depth - 1] : (float2)(0.0f, 0.0f);
      const float2 below = depth > 1 ? carry_in[state.z + depth - 2] : (float2)(0.0f, 0.0f);
      ILANE(start, l) = state.x;
      ILANE(n, l) = depth;
      LANE(top_h, l) = top.x;
      LANE(top_p, l) = top.y;
      LANE(below_h, l) = below.x;
      LANE(below_p, l) = below.y;
#if HFVIS_ROW_SPACING
      LANE(base, l) = as_float(state.w);
#endif
    }
  }
#endif
#if HFVIS_ORIGIN && HFVIS_ROW_SPACING
  // A line that starts here (not resumed) starts at its position along the larger field's line.
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l)
    if (ILANE(start, l) == 0)
      LANE(base, l) = line_start_position(ILANE(c, l), ILANE(r, l), a, b, origin_col, origin_row, whole_width,
                                          whole_height, row_length, row_beyond);
#endif
#if HFVIS_ORIGIN && !HFVIS_ROW_SPACING
  // Positions count from the larger field's line's far end: `shift` receivers more than here.
  const int shift =
      receiver_index(ILANE(c, 0) + origin_col, ILANE(r, 0) + origin_row, a, b, whole_width, whole_height) -
      ILANE(start, 0);
#else
  const int shift = 0;
#endif
#if HFVIS_MAX_DISTANCE
  int block = INT_MIN;  // the block of the stack's samples (none yet)
  int far_part = 0;     // whether window_pass gave this block's receivers the block before
#if HFVIS_STRIPS
#define LINE_OFFSET start
  if (start > 0) {
    // Resuming a line (one per work-item): the block of its last sample before this strip (the
    // receiver start - 1, tau 0) and whether that is not the line's first block, as the sweep
    // there left them (positions computed as the loop below computes them).
#if HFVIS_ROW_SPACING
#define BLOCK_OF(j, tau) \
  block_of_row(j, tau, c, r, a, b, base, row0, width, inv_period, inv_window, row_length, receiver_base)
#define RESUME_BASE base  // receiver -1's position
    // The line's first sample: that of receiver 0 of the whole line (row r + start b).
    const float first_here = line_start_position(c + start * a, r + start * b, a, b, origin_col, origin_row,
                                                 whole_width, whole_height, row_length, row_beyond) -
                             samples[0].tau * (row_length[r + start * b] * inv_period);
    const int first_block = (int)floor(first_here * inv_window);
#else
#define BLOCK_OF(j, tau) block_of(start + shift + (j), tau, period, inv_window)
#define RESUME_BASE 0.0f  // (window_pass takes positions from the index)
    const int first_block = block_of(shift, samples[0].tau, period, inv_window);
#endif
    block = BLOCK_OF(-1, samples[n_samples - 1].tau);
    far_part = block != first_block;
    if (far_part && BLOCK_OF(0, samples[0].tau) == block) {
      // The strip starts inside a block: its receivers here need the block before as well. The
      // block's first sample (ib, qb), periods counted from this strip's first receiver; the
      // pass runs above the carried stack, which the block's own sweep goes on with.
      int ib = 0, qb = 0;
      for (;;) {
        const int pi = qb > 0 ? ib : ib - 1, pq = qb > 0 ? qb - 1 : n_samples - 1;
        if (BLOCK_OF(pi, samples[pq].tau) != block) break;
        ib = pi;
        qb = pq;
      }
      window_pass(heights, width, height, row0, out_row0, samples, segments, n_samples, a, b, period, window, inv_window,
                  drop, c - ib * a, r - ib * b, receivers, stack + n * entry, entry, ib, qb, block,
                  trips, start, shift, RESUME_BASE, inv_period, row_length, receiver_base, stacks, window_far);
    }
#undef BLOCK_OF
#undef RESUME_BASE
  }
#else
#define LINE_OFFSET 0
#endif
#endif
  // The position of the sample before the next one: the last receiver before this launch (a
  // resumed line), or any value for a line's first period, whose first segment always ends
  // outside the field.
#if HFVIS_ROW_SPACING
  lane_float here_before = base;
#elif HFVIS_STRIPS
  lane_float here_before = LANE_FLOAT(start + shift - 1) * period;
#else
  lane_float here_before = (float)(shift - 1) * period;
#endif
  // The corners the last two samples read (lane_sample_height), for segment_peak.
  lane_float far0 = 0.0f, far1 = 0.0f, near0 = 0.0f, near1 = 0.0f;
  for (int i = 0; i < trips; ++i, c -= a, r -= b) {
    const lane_int live = i < receivers;
    const lane_int along = start + i;  // the receivers' index along their whole lines
#if HFVIS_ROW_SPACING
    // The period from the receivers toward +(a, b): its ground length and terms by row.
    lane_float period_length, cos_az, sin_az, weight_l, swath_l;
#pragma unroll
    for (int l = 0; l < HFVIS_LANES; ++l) {
      const int row = ILANE(live, l) ? ILANE(r, l) : 0;
      const float4 terms = row_terms[row];
      LANE(period_length, l) = row_length[row];
      LANE(cos_az, l) = terms.x;
      LANE(sin_az, l) = terms.y;
      LANE(weight_l, l) = terms.z;
      LANE(swath_l, l) = terms.w;
    }
    base = select(base, base + period_length, live & (along > 0));  // kept where a line has ended (carried)
#if HFVIS_MAX_DISTANCE
    // The window's pass reads the positions of the receivers behind (one line per work-item).
    if (live) receiver_base[(r - row0) * width + c] = base;
#endif
    const lane_float tau_scale = period_length * inv_period;  // units per pixel of tau
    const lane_float period_ground_l = period_length * ground_per_pixel;
#elif HFVIS_STRIPS
    const lane_float base = LANE_FLOAT(along + shift) * period;  // the receivers' position along their lines
#else
    // Every line starts at its far end (along = i): one position for all lanes, a scalar (a
    // lane vector of positions made the whole sweep 35 % slower on the AVX-512 CPU).
    const float base = (float)(shift + i) * period;
#endif
#if !HFVIS_ROW_SPACING
    const lane_float cos_az = (lane_float)cos_azimuth, sin_az = (lane_float)sin_azimuth;
    const lane_float weight_l = (lane_float)weight, swath_l = (lane_float)swath;
    const lane_float period_ground_l = (lane_float)period_ground;
#endif
    lane_float h;  // the sample's heights, finally the receivers'
    for (int q = 0; q < n_samples; ++q) {
      __global const LatticeSample* s = samples + q;
#if HFVIS_ROW_SPACING
      const lane_float here = base - s->tau * tau_scale;
#elif HFVIS_STRIPS
      const lane_float here = base - s->tau;
#else
      const float here = base - s->tau;
#endif
#if HFVIS_MAX_DISTANCE
      const int sample_block = (int)floor(here * inv_window);
      if (sample_block != block) {
        far_part = block != INT_MIN;
        if (far_part)
          window_pass(heights, width, height, row0, out_row0, samples, segments, n_samples, a, b, period, window,
                      inv_window, drop, c, r, receivers, stack, entry, i, q, sample_block, trips, LINE_OFFSET,
                      shift, base, inv_period, row_length, receiver_base, stacks, window_far);
        block = sample_block;
        n = 0;
      }
#endif
      lane_int valid;
      // Only a line's first period can reach outside the field (a later one lies between two
      // receivers); testing every lane's first period here costs the same and changes nothing.
      h = lane_sample_height(heights, width, height, row0, s, c, r, live, i == 0, &valid, &near0, &near1);
#if HFVIS_CURVATURE
      // The Earth's drop below the receiver p, drop (p - here)^2, is a parabola along the line:
      // subtracting drop * here^2 from every sample instead changes every slope from p by the
      // same 2 drop p (restored at the receiver), so the hull and its answers stay exact.
      const lane_float hs = h - drop * here * here;
#else
      const lane_float hs = h;
#endif
      // The surface's peak inside the segment from the sample before (at here_before) to this
      // one, where it lies strictly inside (segment_peak), from the corners the two samples read
      // (far0, far1, near0, near1) and those they did not. It lies between the sample before
      // (the stack's top before this sample) and this sample, so it belongs to the hull of all
      // samples so far exactly where it is steeper seen from this sample than this sample's
      // occluder (rise, run, which hull_pop finds); elsewhere this sample's push would pop it at
      // once, and the stack is already what pushing both would leave. So the peak is decided
      // between the two halves of the sample's step: where it is on the hull it is pushed (its
      // own pops start where the sample's stopped: what they popped lies below the line from
      // the sample to its occluder, hence below the peak's view too, as pushing the peak first
      // would have popped it), and the sample then goes on top of it with the peak as its
      // occluder (the peak is steeper from it than the steepest sample, so its pops, which read
      // no entry where nothing pops, find nothing to pop but in a tie). With a
      // maximum distance, only a peak in this sample's block (one in the block before, when
      // this sample starts a block, is window_pass's).
      const lane_float here_lanes = here;
      hull_pop(stacks, stack, entry, valid, hs, here_lanes, 1.0f, &n, &top_h, &top_p, &below_h, &below_p, &rise,
               &run);
      const __global CellSegment* g = segments + q;
      if (g->curved) {
        const SegmentQuadratic w = segment_quadratic(heights, width, height, row0, g, c, r, live, i == 0,
                                                     i > 0 || q > 0, far0, far1, near0, near1, q == n_samples - 1);
        // Seen from this sample, the peak (at u = -B / 2C of the segment's span) rises
        // -(B / 2 + C) over (1 - u) span: a slope of -(B / 2 + C) / span, compared with the
        // occluder's rise / run without a division (both runs are positive), and without the
        // peak's height and position, which only a peak on the hull needs (a peak on the hull
        // is rare: most segments are convex or flat along the line, or their peak is hidden).
        // With the Earth's drop the slope grows by drop (here + here_peak).
#if HFVIS_ROW_SPACING
        const lane_float span = (g->tau_far - g->tau_near) * tau_scale;
#else
        const float span = g->tau_far - g->tau_near;
#endif
#if HFVIS_CURVATURE
        const lane_float u = w.B / (-2.0f * w.C);
        const lane_float peak_rise = -(0.5f * w.B + w.C) + drop * (here + (here - (1.0f - u) * span)) * span;
#else
        const lane_float peak_rise = -(0.5f * w.B + w.C);
#endif
        lane_int on_hull = w.candidate & valid & ((run <= 0.0f) | (peak_rise * run > rise * span));
        if (ANY_LANE(on_hull)) {
          lane_int finite;
          lane_float tau_peak;
          const lane_float h_peak = segment_peak_height(g, w, &tau_peak, &finite);
#if HFVIS_ROW_SPACING
          const lane_float here_peak = base - tau_peak * tau_scale;
#else
          const lane_float here_peak = base - tau_peak;
#endif
          // Strictly between the two samples (u may round to an end).
          on_hull = on_hull & finite & (here_peak > here_before) & (here_peak < here);
#if HFVIS_MAX_DISTANCE
          on_hull = on_hull & (LANE_INT(floor(here_peak * inv_window)) == block);
#endif
          if (ANY_LANE(on_hull)) {
            const lane_float hs_peak = HFVIS_STACK_HEIGHT(h_peak, here_peak);
            lane_float unused_rise = 0.0f, unused_run = 0.0f;
            hull_step(stacks, stack, entry, on_hull, hs_peak, here_peak, 1.0f, &n, &top_h, &top_p, &below_h,
                      &below_p, &unused_rise, &unused_run);
            // The sample's pops again, now from the peak: none, but where rounding decides the
            // peak's slope against its occluder otherwise than the slope above did (then the
            // peak goes, and the stack stays convex as its comparisons see it).
            hull_pop(stacks, stack, entry, on_hull, hs, here_lanes, 1.0f, &n, &top_h, &top_p, &below_h, &below_p,
                     &rise, &run);
          }
        }
      }
      hull_push(stacks, stack, entry, valid, hs, here_lanes, &n, &top_h, &top_p, &below_h, &below_p);
      here_before = here;
      far0 = near0;
      far1 = near1;
    }
#if HFVIS_MAX_DISTANCE
    if (far_part) {
      // The steeper of the block's own occluder and the block before's (which wins ties: it
      // is farther).
      lane_float rise2, run2;
#pragma unroll
      for (int l = 0; l < HFVIS_LANES; ++l) {
        const float2 f = window_far[ILANE(live, l) ? (uint)((ILANE(r, l) - out_row0) * width + ILANE(c, l)) : 0u];
        LANE(rise2, l) = f.x;
        LANE(run2, l) = f.y;
      }
      const lane_int use2 = (run2 > 0.0f) & ((run <= 0.0f) | (rise2 * run >= rise * run2));
      rise = select(rise, rise2, use2);
      run = select(run, run2, use2);
    }
#if !HFVIS_ROW_SPACING
    // The surface at the window's far end, the maximum distance from the receiver exactly: the
    // surface between the last sample within it and the first beyond rises there too (toward a
    // wall just beyond it), which no sample sees. The farthest point of the window, it wins ties;
    // outside the field or beside nodata it is absent. (With per-row spacing, where the window is
    // ground length, not taken.)
    {
      // The point lies reach (a, b) from the receiver; placed in the larger field's pixels and
      // moved back (exactly), a cut of it takes the very fractions the larger field's run does.
      const float reach = window / period;
      lane_float end_h;
#pragma unroll
      for (int l = 0; l < HFVIS_LANES; ++l) {
        const float px = ((float)(ILANE(c, l) + origin_col) + (float)a * reach) - (float)origin_col;
        const float py = ((float)(ILANE(r, l) + origin_row) + (float)b * reach) - (float)origin_row;
        // (inside the field exactly: sample_height_rows clamps, and a point past the edge by
        // inside_field's margin read the border's surface up to a dozen pixels along it)
        const int inside = px >= 0.0f && px <= (float)(width - 1) && py >= 0.0f && py <= (float)(height - 1);
        LANE(end_h, l) = ILANE(live, l) && inside ? sample_height_rows(heights, width, height, row0, px, py) : NAN;
      }
      const lane_float end_rise = HFVIS_STACK_HEIGHT(end_h, base - window) - HFVIS_STACK_HEIGHT(h, base);
      const lane_int use_end = !isnan(end_rise) & ((run <= 0.0f) | (end_rise * run >= rise * window));
      rise = select(rise, end_rise, use_end);
      run = select(run, (lane_float)window, use_end);
    }
#endif
#endif
    // The receivers (the last sample of the period, h its height): the steeper of the hull's
    // occluder and the limit at the receiver, compared without a division (both runs are
    // positive); the occluder wins ties (it is the farther point casting that elevation).
    // With curvature the near limit is unchanged (the drop is of second order in distance).
    const lane_float near = near_rise(heights, width, height, row0, live, c, r, h, a, b);
    const lane_float ground = run * ground_per_pixel;
#if HFVIS_CURVATURE
    const lane_float far_rise = rise - 2.0f * drop * base * run;
#else
    const lane_float far_rise = rise;
#endif
    const lane_int has_far = run > 0.0f, has_near = !isnan(near);
    const lane_int use_near = has_near & (!has_far | (near * ground > far_rise * period_ground_l));
    const lane_float distance = select((lane_float)0.0f, ground, has_far & !use_near);
#if HFVIS_HAS_NODATA
    const lane_int nodata = isnan(h);
#else
    const lane_int nodata = 0;
#endif
    emit_lanes(live, (r - out_row0) * width + c, nodata, has_far | has_near, select(far_rise, near, use_near),
               select(ground, period_ground_l, use_near), distance, cos_az, sin_az, weight_l, swath_l, plane,
               normals, angles, distances, svf_sum, ao_sum HFVIS_ENV_ARGS);
  }
#if HFVIS_STRIPS
#pragma unroll
  for (int l = 0; l < HFVIS_LANES; ++l) {
    if (first + l < n_lines) {
      __global int4* state = line_state + first + l;
      state->y = ILANE(n, l);
#if HFVIS_ROW_SPACING
      state->w = as_int(LANE(base, l));
#endif
    }
  }
#endif
}

// The hull stacks that lines take on into the next strip (see horizon_lattice): line j's
// line_state[j].y entries from stacks[lines[j].w + k stride] to carry_out[offsets[j] + k];
// lines with offsets[j] < 0 end in this strip. One work-item per line. Global size: n_lines
// rounded up.
__kernel void carry_stacks(__global const int4* lines, __global const int4* line_state,
                           __global const int* offsets, int n_lines, __global const float2* stacks, uint stride,
                           __global float2* carry_out) {
  const int j = get_global_id(0);
  if (j >= n_lines || offsets[j] < 0) return;
  const int depth = line_state[j].y, stack = lines[j].w, at = offsets[j];
  for (int k = 0; k < depth; ++k) carry_out[at + k] = stacks[stack + k * (int)stride];
}

#if HFVIS_ROW_SPACING
// The naive march's ground length per pixel at row y (fractional), linear between the rows of
// the table (one entry per row), clamped to the field.
HFVIS_INLINE float row_ground_at(__global const float* row_length, int height, float y) {
  const float clamped = clamp(y, 0.0f, (float)(height - 1));
  const int r0 = (int)clamped;
  const int r1 = min(r0 + 1, height - 1);
  const float w = clamped - (float)r0;
  return (1.0f - w) * row_length[r0] + w * row_length[r1];
}
#endif

// Naive method (Timonen 2013, Sec. 1): for every pixel, march the ray in steps of
// step_length pixels along (dir_x, dir_y), sample bilinearly and keep the steepest slope.
// One direction per launch, its geometry passed as arguments (uniform for certain, no
// per-step loads). The trip count is the same for the whole work-group (tile_reach: the
// longest ray of the group's tile), and a barrier ends every step: PoCL runs the work-items
// inside each step, the
// one loop it vectorises (the march ran 5x faster that way on PoCL); samples past a
// pixel's own exit are masked; with a maximum distance the march ends after `max_steps`
// (else INT_MAX) and takes the surface at the distance itself, `max_reach` pixels along the ray
// (INFINITY for none), as the sweep does (between the last step and the first beyond it the
// surface may rise toward a wall out of reach). With HFVIS_ROW_SPACING the ray is straight in
// pixels and its ground length is summed step by step, a maximum distance is `max_ground` of it
// (INFINITY for none; then max_steps is INT_MAX), row_length[r] is the ground length per pixel
// along it at row r, row_terms[r] its unit ground direction, weight and swath there, and drop is
// per ground unit squared. Global size: (W, H) rounded up to the local size (the tile).
__kernel void horizon_naive(__global const float* heights, int width, int height, float dir_x, float dir_y,
                            float step_length, float ground_per_pixel, float drop, int max_steps,
                            float max_reach, float max_ground, __global const float* row_length,
                            __global const float4* row_terms, float cos_azimuth, float sin_azimuth,
                            float weight, float swath, uint plane, __global const float2* normals,
                            __global float* angles, __global float* distances, __global float* svf_sum,
                            __global float* ao_sum HFVIS_ENV_PARAMS) {
  int c = get_global_id(0), r = get_global_id(1);
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  const float h = heights[pixel];
  const int steps = min((int)(tile_reach(dir_x, dir_y, width, height) / step_length) + 1, max_steps);
  float best_rise = 0.0f;  // height gain to the steepest sample so far
  int best_step = 0;       // its step, 0 = none yet
#if HFVIS_ROW_SPACING
  float along = 0.0f, best_along = 0.0f;  // ground length of the ray so far, to the steepest sample
#endif
  for (int i = 1; i <= steps; ++i) {
    float t = (float)i * step_length;
    float px = (float)cc + t * dir_x, py = (float)rr + t * dir_y;
    float q = sample_height(heights, width, height, px, py);
#if HFVIS_ROW_SPACING
    // This step's ground length: the ground length per pixel along the ray at its middle row.
    along += step_length * row_ground_at(row_length, height, (float)rr + ((float)i - 0.5f) * step_length * dir_y);
    const float g = along;
#else
    const float g = t;
#endif
#if HFVIS_CURVATURE
    float rise = q - h - drop * g * g;  // the Earth's drop at g (drop per unit of g, squared)
#else
    float rise = q - h;
#endif
#if HFVIS_ROW_SPACING
    int steeper = rise * best_along >= best_rise * along;
#else
    // rise / i >= best_rise / best_step without a division; ties go to the farther sample.
    int steeper = rise * (float)best_step >= best_rise * (float)i;
#endif
    int better = inside_field(px, py, width, height) & !isnan(q) & ((best_step == 0) | steeper);
#if HFVIS_ROW_SPACING
    better &= g <= max_ground;  // within the maximum distance (ground length: max_steps is all)
#endif
    best_rise = better ? rise : best_rise;
    best_step = better ? i : best_step;
#if HFVIS_ROW_SPACING
    best_along = better ? along : best_along;
#endif
    barrier(CLK_LOCAL_MEM_FENCE);
  }
#if !HFVIS_ROW_SPACING
  // The surface at the maximum distance itself, the farthest point within it (it wins ties),
  // where it lies past the last step, inside the field and on the surface. (With per-row
  // spacing, where the distance is ground length, not taken, as in the sweep.)
  float best_t = (float)best_step * step_length;
  if (max_reach > (float)steps * step_length) {
    const float px = (float)cc + max_reach * dir_x, py = (float)rr + max_reach * dir_y;
    const float q = px >= 0.0f && px <= (float)(width - 1) && py >= 0.0f && py <= (float)(height - 1)
                        ? sample_height(heights, width, height, px, py)
                        : NAN;
#if HFVIS_CURVATURE
    const float rise = q - h - drop * max_reach * max_reach;
#else
    const float rise = q - h;
#endif
    if (!isnan(rise) && (best_step == 0 || rise * best_t >= best_rise * max_reach)) {
      best_rise = rise, best_t = max_reach;
      best_step = max(best_step, 1);  // (a sample found: only its being non-zero counts below)
    }
  }
#endif
#if HFVIS_ROW_SPACING
  const float ground = best_along;
  const float4 terms = row_terms[rr];
  const float cos_az = terms.x, sin_az = terms.y, weight_r = terms.z, swath_r = terms.w;
#else
  const float ground = best_t * ground_per_pixel;
  const float cos_az = cos_azimuth, sin_az = sin_azimuth, weight_r = weight, swath_r = swath;
#endif
  const float distance = best_step > 0 ? ground : 0.0f;
  if (valid)
    emit_direction(pixel, isnan(h), best_step > 0, best_rise, ground, distance, cos_az, sin_az, weight_r,
                   swath_r, plane, normals, angles, distances, svf_sum, ao_sum HFVIS_ENV_ARGS);
}
