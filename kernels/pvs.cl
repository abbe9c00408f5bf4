// pvs.cl: the height-field ray caster of the potentially visible sets (hfvis/pvs.hpp; the
// host in src/ops/pvs.cpp): one work-item per ray, shared/heightfield_ray.cl's first hit and,
// with `cap` > 0, the view cells the ray's free part passes through.
//
// Layouts, as the context's line layout: line-major (each ray's 8 floats contiguous, a ray's
// view cells contiguous: ray r's entry c at r * 8 + c, its view cell j at r * cap + j; for CPUs)
// or step-major (one plane per entry: c * n + r, j * n + r; neighbouring work-items read and
// write neighbouring words, for GPUs). A ray is (ox, oy, oz, dx, dy, dz, t_max, unused).
#pragma OPENCL FP_CONTRACT OFF

#include "shared/heightfield_ray.cl"

__kernel void pvs_cast(__global const float* h, int width, int height, __global const float* pyramid,
                       __global const int* levels, int top, __global const float* rays, int n, int line_major,
                       int view, int view_x, float band_lo, float band_hi, int cap, __global float* hit_t,
                       __global int* hit_cell, __global int* counts, __global int* pierced,
                       __global float* pierced_t) {
  const int r = get_global_id(0);
  if (r >= n) return;
  const size_t base = line_major ? (size_t)r * 8 : (size_t)r;
  const size_t step = line_major ? 1 : (size_t)n;
  __global const float* ray = rays + base;
  const size_t list = line_major ? (size_t)r * cap : (size_t)r;
  const int stride = line_major ? 1 : n;
  int count = 0, cell = -1;
  hit_t[r] = hf_ray_cast(h, width, height, pyramid, levels, top, ray[0], ray[step], ray[2 * step],
                         ray[3 * step], ray[4 * step], ray[5 * step], ray[6 * step], view, view_x, band_lo,
                         band_hi, cap, pierced + list, pierced_t + list, stride, &count, &cell);
  hit_cell[r] = cell;
  counts[r] = count;
}
