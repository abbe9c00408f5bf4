// bounce.cl: one diffuse light bounce (Timonen 2013, Sec. 10.1, alternative 3): the
// presampling of exit radiance and receiver normals along the sweep lines, and the
// reduction of the gathered irradiance onto the grid. The gather itself runs inside the
// convex hull tree sweep of intervisibility.cl (HFVIS_WANT_BOUNCE), over the visible runs
// the tree finds; include/hfvis/bounce.hpp states the formula.
//
// Compile-time parameters, besides those of intervisibility.cl and sweep_framework.cl:
//   HFVIS_CHANNELS  radiance channels, 1..4 (default 1)
#ifndef HFVIS_WANT_BOUNCE
#define HFVIS_WANT_BOUNCE 1
#endif
#include "intervisibility.cl"

// Per (line, step) of the batch: the exit radiance channels sampled bilinearly at the
// sample's position (as its height), then the unit normal there: the bilinear
// interpolation of the pixel normals, renormalised. `radiance` holds HFVIS_CHANNELS planes
// and `normals` three planes (x, y, z) of width*height, NaN at nodata pixels (so that a
// sample uses the same valid corners as its height). Global size as presample_lines.
__kernel void bounce_presample(__global const float* radiance, __global const float* normals, int width,
                               int height, __global const SweepDirection* directions,
                               __global float* attributes) {
#if HFVIS_LINE_MAJOR
  int step = get_global_id(0), line = get_global_id(1);
#else
  int line = get_global_id(0), step = get_global_id(1);
#endif
  const SweepDirection d = load_direction(directions + get_global_id(2));
  if (line >= d.n_lines || step >= d.n_steps) return;
  const uint plane = (uint)(width * height);
  float x, y;
  sweep_position(d, line, step, &x, &y);
  __global float* out = attributes + line_entry(d, line, step) * HFVIS_BOUNCE_STRIDE;
  for (int c = 0; c < HFVIS_CHANNELS; ++c)
    out[c] = sample_height(radiance + (uint)c * plane, width, height, x, y);
  float nx = sample_height(normals, width, height, x, y);
  float ny = sample_height(normals + plane, width, height, x, y);
  float nz = sample_height(normals + 2u * plane, width, height, x, y);
  float length = sqrt(nx * nx + ny * ny + nz * nz);
  out[HFVIS_CHANNELS] = nx / length;
  out[HFVIS_CHANNELS + 1] = ny / length;
  out[HFVIS_CHANNELS + 2] = nz / length;
}

// For every receiver pixel and every direction of the batch, the bilinear interpolation of
// the irradiance of the (up to) four surrounding line entries (absent ones left out and the
// weights renormalised, none left: nothing gathered), added to the run's sums
// (HFVIS_CHANNELS planes); NaN at nodata pixels. Straight-line code with a uniform
// barrier, as intervisibility_reduce. Global size: (W, H) rounded up to the local size.
__kernel void bounce_reduce(__global const float* heights, int width, int height,
                            __global const SweepDirection* directions, int batch_size,
                            __global const float* gathered, __global float* irradiance) {
  int c = get_global_id(0), r = get_global_id(1);
  int valid = c < width && r < height;
  int cc = min(c, width - 1), rr = min(r, height - 1);
  const uint pixel = (uint)(rr * width + cc);
  const uint plane = (uint)(width * height);
  float sums[HFVIS_CHANNELS];
  for (int ch = 0; ch < HFVIS_CHANNELS; ++ch) sums[ch] = 0.0f;
  for (int b = 0; b < batch_size; ++b) {
    barrier(CLK_LOCAL_MEM_FENCE);  // see horizon_naive: keeps the work-item loop innermost
    const SweepDirection d = load_direction(directions + b);
    int j0, i0;
    float fu, fv;
    receiver_cell(d, (float)cc, (float)rr, &j0, &i0, &fu, &fv);
    float weight = 0.0f;
    float acc[HFVIS_CHANNELS];
    for (int ch = 0; ch < HFVIS_CHANNELS; ++ch) acc[ch] = 0.0f;
    for (int k = 0; k < 4; ++k) {
      float w;
      int i;
      __global const float* entry = gathered + cell_corner(d, j0, i0, fu, fv, k, &w, &i) * HFVIS_CHANNELS;
      int use = w > 0.0f && !isnan(entry[0]);
      weight += use ? w : 0.0f;
      for (int ch = 0; ch < HFVIS_CHANNELS; ++ch) acc[ch] += use ? w * entry[ch] : 0.0f;
    }
    // Divide only when weights are missing: a single full weight stays exact.
    int renormalise = weight > 0.0f && weight != 1.0f;
    for (int ch = 0; ch < HFVIS_CHANNELS; ++ch) sums[ch] += renormalise ? acc[ch] / weight : acc[ch];
  }
  if (valid) {
    int nodata = isnan(heights[pixel]);
    for (int ch = 0; ch < HFVIS_CHANNELS; ++ch)
      irradiance[(uint)ch * plane + pixel] = nodata ? NAN : irradiance[(uint)ch * plane + pixel] + sums[ch];
  }
}
