// region_visibility.cl: which source samples each receiver sees (computeRegionVisibility and
// computeRegionPairVisibility in src/ops/region_visibility.cpp; the contract in
// hfvis/region_visibility.hpp). One work-item per (receiver, word of 32 source samples): it
// places its receiver and the word's source samples and marches each pair
// (shared/region_visibility_sight.cl; with a culling pyramid, `levels` > 0, the march leaps
// over the blocks of cells far below the segment), then writes the word, so no two work-items write one word and no
// atomics are needed.
//
// Receivers are the grid points (`pixel_receivers`) or the samples of a second region (the
// table `receivers`, stream 0). The words are stored receiver-major (word w of receiver r at
// r * words + w: a work-item's words contiguous, for CPUs) or word-major (w * count + r:
// neighbouring work-items write neighbouring words, for GPUs), as the context's line layout.
// The host launches the receivers in chunks from `first`, to bound each launch's time.
#pragma OPENCL FP_CONTRACT OFF

#include "shared/region_visibility_sight.cl"

typedef struct {
  int width, height;     // the field
  float cell_x, cell_y;  // ground units per pixel
  float curvature;       // c of the drop c d^2
  float max_d2;          // the largest squared ground distance of a visible pair; 0 = any
} RegionField;

__kernel void region_visibility_bits(__global const float* h, __global const float* pyramid, int levels,
                                     float margin, RegionField f, __global const float* sources,
                                     int source_absolute, int samples, int pixel_receivers,
                                     __global const float* receivers, int receiver_absolute,
                                     int receiver_count, float target_height, unsigned int seed,
                                     int decorrelate, int words, int receiver_major, int first,
                                     __global unsigned int* bits) {
  const int r = first + (int)get_global_id(0), w = get_global_id(1);
  if (r >= receiver_count || w >= words) return;
  float xr, yr, zr;
  if (!pixel_receivers) {
    region_sample(receivers, h, f.width, f.height, receiver_absolute, seed, 0U, r, &xr, &yr, &zr);
  } else {
    xr = (float)(r % f.width);
    yr = (float)(r / f.width);
    zr = h[r] + target_height;
  }
  unsigned int word = 0U;
  if (!isnan(zr)) {
    const unsigned int key = decorrelate ? (unsigned int)r + 1U : 0U;
    const int end = 32 * w + 32 < samples ? 32 * w + 32 : samples;
    for (int s = 32 * w; s < end; ++s) {
      float xs, ys, zs;
      region_sample(sources, h, f.width, f.height, source_absolute, seed, key, s, &xs, &ys, &zs);
      if (region_sight_visible_culled(h, f.width, f.height, f.cell_x, f.cell_y, f.curvature, f.max_d2, pyramid,
                                      levels, margin, xs, ys, zs, xr, yr, zr))
        word |= 1U << (s - 32 * w);
    }
  }
  bits[receiver_major ? (size_t)r * words + w : (size_t)w * receiver_count + r] = word;
}
