// bounce.cl: the one-bounce gather (Timonen 2013, Sec. 10.1, alternative 3;
// include/hfvis/bounce.hpp states the formula), included by intervisibility.cl when
// HFVIS_WANT_BOUNCE is set: the lattice sweep visits each receiver's visible samples and peaks, and
// these helpers turn them into the receiver's irradiance. Mirrored by BounceGather in
// src/core/scalar_hull_tree.cpp.
//
// For one receiver, the visible samples and peaks are visited farthest first (the runs of the
// horizons, each from its horizon toward the receiver); a peak's radiance lies between its two
// samples', as its position does. A node's elevation band reaches
// up to the mean of its and its farther neighbour's elevations when the two are adjacent
// (no hidden sample between), else up to its own elevation (the gap's band went to the
// farther sample); it reaches down likewise toward its nearer neighbour, the nearest one down to
// the tangent elevation (the surface between the receiver and it). Each band adds
// radiance * (G(upper) - G(lower)), G the wedge integral of the projected solid angle,
// clipped below at the tangent elevation.
//
// Compile-time parameters: HFVIS_CHANNELS, radiance channels 1..4 (default 1).
#ifndef HFVIS_BOUNCE_CL
#define HFVIS_BOUNCE_CL

#ifndef HFVIS_CHANNELS
#define HFVIS_CHANNELS 1
#endif

typedef struct {
  float nz_term;  // n_z * D / 2 (D: the direction's wedge of azimuth)
  float nh_term;  // (n . d) * 2 sin(D / 2)
  float tangent;  // lower clip of G: where its wedge-integrated cosine factor vanishes
  float ground;   // ground length of one step
  float h;        // the receiver's height
  int have_prev;  // a farther visible sample awaits its lower band edge
  int adjacent;   // the next sample visited is adjacent to it
  float prev_theta, prev_g_hi;
  float prev_radiance[HFVIS_CHANNELS];
  float sum[HFVIS_CHANNELS];
} BounceGather;

HFVIS_INLINE float bounce_g(const BounceGather* g, float theta) {
  float t = hf_max(theta, g->tangent);
  float s = sin(t), c = cos(t);
  return g->nz_term * (s * s) + g->nh_term * (0.5f * (t + s * c));
}

// The receiver's unit normal (nx, ny, nz), the direction on the ground, its step's ground
// length, and half_sector = D / 2 and wedge = 2 sin(D / 2) of its wedge D.
HFVIS_INLINE void bounce_begin(BounceGather* g, float nx, float ny, float nz, float cos_azimuth,
                               float sin_azimuth, float step_ground, float h, float half_sector,
                               float wedge) {
  float toward = nx * cos_azimuth + ny * sin_azimuth;
  g->nz_term = nz * half_sector;
  g->nh_term = toward * wedge;
  g->tangent = atan2(-g->nh_term, 2.0f * g->nz_term);
  g->ground = step_ground;
  g->h = h;
  g->have_prev = 0;
  g->adjacent = 0;
  g->prev_theta = 0.0f;
  g->prev_g_hi = 0.0f;
  for (int c = 0; c < HFVIS_CHANNELS; ++c) g->prev_radiance[c] = g->sum[c] = 0.0f;
}

// Visible node (a sample, or a peak of the surface between two) at height hx, `distance` steps
// from the receiver, with exit radiance `radiance`, nearer than every node visited before it.
HFVIS_INLINE void bounce_visit(BounceGather* g, float hx, float distance, const float* radiance) {
  float theta = atan2(hx - g->h, distance * g->ground);
  float g_hi;
  if (!g->have_prev) {
    g_hi = bounce_g(g, theta);
  } else {
    float edge = g->adjacent ? 0.5f * (g->prev_theta + theta) : theta;
    float g_edge = bounce_g(g, edge);
    for (int c = 0; c < HFVIS_CHANNELS; ++c) g->sum[c] += g->prev_radiance[c] * (g->prev_g_hi - g_edge);
    g_hi = g_edge;
  }
  g->prev_theta = theta;
  g->prev_g_hi = g_hi;
  for (int c = 0; c < HFVIS_CHANNELS; ++c) g->prev_radiance[c] = radiance[c];
  g->have_prev = 1;
  g->adjacent = 1;
}

// The nearest visible sample's band reaches down to the tangent clip (the surface between the
// receiver and it, a pit's or a wall's foot's: ended at its own elevation, a pixel whose nearest
// sample is its horizon gathered nothing, a probe's find); gives the sums.
HFVIS_INLINE void bounce_finish(BounceGather* g, float* irradiance) {
  if (g->have_prev) {
    float g_lo = bounce_g(g, g->tangent);
    for (int c = 0; c < HFVIS_CHANNELS; ++c) g->sum[c] += g->prev_radiance[c] * (g->prev_g_hi - g_lo);
  }
  for (int c = 0; c < HFVIS_CHANNELS; ++c) irradiance[c] = g->sum[c];
}

// The exit radiance at step x of a lattice line (`line`, as intervisibility_lattice reads it),
// sampled like its height: the receiver's pixel as it is, other samples bilinearly over the
// valid corners (`radiance` is NaN at nodata pixels). HFVIS_CHANNELS planes of `plane` floats.
HFVIS_INLINE void lattice_radiance(__global const float* radiance, int width, uint plane, int4 line,
                                   __global const LatticeSample* samples, int n_samples, int a, int b, int x,
                                   float* out) {
  const int i = x / n_samples, q = x - i * n_samples;
  __global const LatticeSample* s = samples + q;
  const int ex = s->ex, ey = s->ey;
  const uint at = (uint)((line.y - i * b + s->oy) * width + (line.x - i * a + s->ox));
  for (int c = 0; c < HFVIS_CHANNELS; ++c) {
    __global const float* channel = radiance + (uint)c * plane;
    out[c] = ex + ey == 0 ? channel[at]
                          : lattice_height(channel, at, (uint)ex, (uint)(ey * width), s->w00, s->w10, s->w01, s->w11);
  }
}

#endif  // HFVIS_BOUNCE_CL
