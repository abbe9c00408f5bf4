// environment_light.cl: irradiance from an HDR environment through the horizons (Timonen &
// Westerholm 2010, Sec. 6.2; hfvis/environment_light.hpp has the derivation). Per direction k of a
// run, a table of `rows` bands of zenith angle theta (band i from i pi / rows to
// (i + 1) pi / rows), each holding per channel six floats (KA, LA, KB, LB, KC, LC): the swath's
// integrals down to a zenith angle theta inside band i are
//   A(theta) = KA + LA q1(theta),  B(theta) = KB + LB q2(theta),  C(theta) = KC + LC q2(theta),
//   q1 = sin^2(theta) / 2,  q2 = (theta - sin(theta) cos(theta)) / 2,
// and the direction adds nz A + toward B + across C at the receiver, for the normal (nx, ny, nz)
// and its components toward the direction and across it (+90 degrees of azimuth).
//
// environment_add is written once in the common subset of OpenCL C and C++: kernels/horizon.cl
// includes it, and so does src/ops/environment_light_terms.hpp for the scalar reference.
#ifndef HFVIS_ENVIRONMENT_CL
#define HFVIS_ENVIRONMENT_CL

#include "shared/fast_math.cl"

#ifdef __OPENCL_VERSION__
#define HFVIS_GLOBAL __global
#else
#define HFVIS_GLOBAL
#endif

// Floats per band and channel of a table.
#define HFVIS_ENV_TERMS 6

// Adds one direction's irradiance at a receiver to its sums (channel c's at sums[c * stride]),
// or makes them NaN at nodata: nz A + toward B + across C at the zenith angle of band `band`, with
// q1 and q2 there (environment_add).
HFVIS_INLINE void environment_accumulate(HFVIS_GLOBAL float* sums, unsigned int stride, int channels, int nodata,
                                         int band, float q1, float q2, float nz, float toward, float across,
                                         HFVIS_GLOBAL const float* table) {
  HFVIS_GLOBAL const float* t = table + band * channels * HFVIS_ENV_TERMS;
  for (int c = 0; c < channels; ++c, t += HFVIS_ENV_TERMS) {
    const float e = nz * (t[0] + t[1] * q1) + toward * (t[2] + t[3] * q2) + across * (t[4] + t[5] * q2);
    HFVIS_GLOBAL float* sum = sums + c * stride;
    *sum = nodata ? NAN : *sum + e;
  }
}

// What environment_accumulate takes at a receiver, for scalars and lane vectors alike: for the
// slope x = tan(e) of the lowest elevation that counts (lower_limit), sin^2(theta) = cos^2(e) =
// 1 / (1 + x^2), sin(theta) cos(theta) = x cos^2(e) and theta = pi / 2 - atan(x), the same pieces
// as ambient_term; the band from the polynomial atan (near a band's edge it may be the next band,
// where the two give the same value up to rounding: the table is continuous across edges); the
// normal's components toward the direction (cos_az, sin_az) and across it (+90 degrees).
#define HFVIS_ENVIRONMENT_TERMS(T, IT, CONVERT_IT)                                                        \
  HFVIS_INLINE HFVIS_OVERLOADABLE void environment_terms(T x, T nx, T ny, T cos_az, T sin_az, int rows,     \
                                                         IT* band, T* q1, T* q2, T* toward, T* across) {    \
    const T cos2 = 1.0f / (1.0f + x * x), zenith = 0.5f * HFVIS_PI_F - hf_atan(x);                          \
    *q1 = 0.5f * cos2;                                                                                      \
    *q2 = 0.5f * (zenith - x * cos2);                                                                       \
    const IT b = CONVERT_IT(zenith * ((float)rows / HFVIS_PI_F));                                           \
    *band = b < 0 ? (IT)0 : (b >= rows ? (IT)(rows - 1) : b);                                               \
    *toward = nx * cos_az + ny * sin_az;                                                                    \
    *across = ny * cos_az - nx * sin_az;                                                                    \
  }
#define HFVIS_CONVERT_INT(v) ((int)(v))
HFVIS_ENVIRONMENT_TERMS(float, int, HFVIS_CONVERT_INT)

// One direction's irradiance at a scalar receiver (the naive march and the scalar reference).
HFVIS_INLINE void environment_add(HFVIS_GLOBAL float* sums, unsigned int stride, int channels, int nodata, float x,
                                  float nx, float ny, float nz, float cos_az, float sin_az,
                                  HFVIS_GLOBAL const float* table, int rows) {
  int band;
  float q1, q2, toward, across;
  environment_terms(x, nx, ny, cos_az, sin_az, rows, &band, &q1, &q2, &toward, &across);
  environment_accumulate(sums, stride, channels, nodata, band, q1, q2, nz, toward, across, table);
}

#ifdef __OPENCL_VERSION__
// cos(a) - cos(b), the solid angle per radian of azimuth between zenith angles a < b, without the
// cancellation of the difference near the zenith (bands of 65536 rows).
inline float solid_between(float a, float b) { return 2.0f * sin(0.5f * (a + b)) * sin(0.5f * (b - a)); }

// The tables of every direction, one work-item per direction (a table costs the map's rows
// times the columns of its swath: microseconds, next to the sweep's N^2 per direction).
// env: the map's planes (channel c at c * env_width * env_height), row 0 at the zenith.
// Direction k's swath is bins [spans[k].x, spans[k].x + spans[k].y) of `bins`, each bin
// (lo, hi, edge, column): its azimuths relative to the direction's, lo .. hi, and the first
// map column it overlaps, `column` (any integer, taken modulo the width), whose left edge is at
// relative azimuth `edge`. A band of the table takes the mean of the map's rows it spans,
// weighted by solid angle; its zenith integrals are exact. Global size: directions rounded up.
__kernel void environment_tables(__global const float* env, int env_width, int env_height, int channels,
                                 int rows, int directions, __global const float4* bins,
                                 __global const int2* spans, __global float* tables) {
  const int k = get_global_id(0);
  if (k >= directions) return;
  const float column_width = 2.0f * HFVIS_PI_F / (float)env_width;
  const int2 span = spans[k];
  float cum_a[3] = {0.0f, 0.0f, 0.0f}, cum_b[3] = {0.0f, 0.0f, 0.0f}, cum_c[3] = {0.0f, 0.0f, 0.0f};
  __global float* out = tables + (size_t)k * rows * channels * HFVIS_ENV_TERMS;
  for (int i = 0; i < rows; ++i) {
    const float theta0 = (float)i * HFVIS_PI_F / (float)rows, theta1 = (float)(i + 1) * HFVIS_PI_F / (float)rows;
    const float band_solid = solid_between(theta0, theta1);
    float sa[3] = {0.0f, 0.0f, 0.0f}, sb[3] = {0.0f, 0.0f, 0.0f}, sc[3] = {0.0f, 0.0f, 0.0f};
    // The map's rows the band spans (with the map's own rows, row i alone, wholly).
    const int same = env_height == rows;
    const int j0 = same ? i : max(0, (int)floor(theta0 * (float)env_height / HFVIS_PI_F));
    const int j1 = same ? i + 1 : min(env_height, (int)ceil(theta1 * (float)env_height / HFVIS_PI_F));
    for (int j = j0; j < j1; ++j) {
      const float a = fmax(theta0, (float)j * HFVIS_PI_F / (float)env_height);
      const float b = fmin(theta1, (float)(j + 1) * HFVIS_PI_F / (float)env_height);
      const float share = same ? 1.0f : solid_between(a, b) / band_solid;  // the row's share of the band
      if (!(share > 0.0f)) continue;
      for (int q = span.x; q < span.x + span.y; ++q) {
        const float4 bin = bins[q];
        // Each column's left edge from its own count (a running sum would drift over wide swaths).
        for (int n = 0;; ++n) {
          const float edge = bin.z + (float)n * column_width;
          if (!(edge < bin.y)) break;
          const int column = (int)bin.w + n;
          const float lo = fmax(edge, bin.x), hi = fmin(edge + column_width, bin.y);
          if (!(hi > lo)) continue;
          // The column's azimuths lo .. hi: their measure, and the integrals of cos and sin.
          const float w0 = hi - lo, w1 = sin(hi) - sin(lo), w2 = cos(lo) - cos(hi);
          const int col = ((column % env_width) + env_width) % env_width;
          for (int c = 0; c < channels; ++c) {
            const float radiance = share * env[((size_t)c * env_height + j) * env_width + col];
            sa[c] += radiance * w0;
            sb[c] += radiance * w1;
            sc[c] += radiance * w2;
          }
        }
      }
    }
    // q1 and q2 at the band's edges.
    const float s0 = sin(theta0), c0 = cos(theta0), s1 = sin(theta1), c1 = cos(theta1);
    const float q1_0 = 0.5f * s0 * s0, q1_1 = 0.5f * s1 * s1;
    const float q2_0 = 0.5f * (theta0 - s0 * c0), q2_1 = 0.5f * (theta1 - s1 * c1);
    for (int c = 0; c < channels; ++c, out += HFVIS_ENV_TERMS) {
      out[0] = cum_a[c] - sa[c] * q1_0;
      out[1] = sa[c];
      out[2] = cum_b[c] - sb[c] * q2_0;
      out[3] = sb[c];
      out[4] = cum_c[c] - sc[c] * q2_0;
      out[5] = sc[c];
      cum_a[c] += sa[c] * (q1_1 - q1_0);
      cum_b[c] += sb[c] * (q2_1 - q2_0);
      cum_c[c] += sc[c] * (q2_1 - q2_0);
    }
  }
}
#endif

#endif  // HFVIS_ENVIRONMENT_CL
