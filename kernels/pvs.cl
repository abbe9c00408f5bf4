// pvs.cl: the height-field ray caster of the potentially visible sets (hfvis/pvs.hpp; the
// host in src/ops/pvs.cpp): one work-item per ray, shared/heightfield_ray.cl's first hit and,
// in pvs_cast_lists, the view cells the ray's free part passes through.
//
// Layouts, as the context's line layout: line-major (each ray's 8 floats contiguous, a ray's
// view cells contiguous: ray r's entry c at r * 8 + c, its view cell j at r * cap + j; for CPUs)
// or step-major (one plane per entry: c * n + r, j * n + r; neighbouring work-items read and
// write neighbouring words, for GPUs). A ray is (ox, oy, oz, dx, dy, dz, t_max, unused).
#pragma OPENCL FP_CONTRACT OFF

#include "shared/heightfield_ray.cl"

// Casts ray r (< n): its hit into hit_t[r], hit_cell[r]; with cap > 0 its view cells into
// pierced / pierced_t in the layout's list r. Returns how many.
inline int pvs_cast_ray(__global const float* h, int width, int height, __global const float* pyramid,
                        __global const int* levels, int top, __global const float* rays, int n,
                        int line_major, float curvature, float cell_x, float cell_y, int view, int view_x,
                        float band_lo, float band_hi, int cap, __global float* hit_t, __global int* hit_cell,
                        __global int* pierced, __global float* pierced_t, int r) {
  const size_t base = line_major ? (size_t)r * 8 : (size_t)r;
  const size_t step = line_major ? 1 : (size_t)n;
  __global const float* ray = rays + base;
  const size_t list = cap == 0 ? 0 : (line_major ? (size_t)r * cap : (size_t)r);  // no list: no buffer
  const int stride = line_major ? 1 : n;
  int count = 0, cell = -1;
  hit_t[r] =
      hf_ray_cast(h, width, height, pyramid, levels, top, ray[0], ray[step], ray[2 * step], ray[3 * step],
                  ray[4 * step], ray[5 * step], ray[6 * step], curvature, cell_x, cell_y, view, view_x,
                  band_lo, band_hi, cap, pierced + list, pierced_t + list, stride, &count, &cell);
  hit_cell[r] = cell;
  return count;
}

// The hits alone.
__kernel void pvs_cast(__global const float* h, int width, int height, __global const float* pyramid,
                       __global const int* levels, int top, __global const float* rays, int n, int line_major,
                       float curvature, float cell_x, float cell_y, int view, int view_x, float band_lo,
                       float band_hi, __global float* hit_t, __global int* hit_cell) {
  const int r = get_global_id(0);
  if (r >= n) return;
  pvs_cast_ray(h, width, height, pyramid, levels, top, rays, n, line_major, curvature, cell_x, cell_y, view,
               view_x, band_lo, band_hi, 0, hit_t, hit_cell, 0, 0, r);
}

// The hits and the view-cell lists (cap > 0), each list cast into `pierced` / `pierced_t` and
// then packed with the work-group's others into `lists`: work-group g's lists one after another
// from pair g * (local size) * cap, ray by ray, each entry the pair (view cell, its t's bits), the
// lengths in counts[r]. So the host reads a few used pairs per ray (about one: most rays list
// the view cell they start in, a few its neighbours) rather than every list's whole capacity,
// and finds ray r's list from the lengths before it in its group. `group_counts`: one int per
// work-item of a group.
__kernel void pvs_cast_lists(__global const float* h, int width, int height, __global const float* pyramid,
                             __global const int* levels, int top, __global const float* rays, int n,
                             int line_major, float curvature, float cell_x, float cell_y, int view,
                             int view_x, float band_lo, float band_hi, int cap, __global float* hit_t,
                             __global int* hit_cell, __global int* counts, __global int* pierced,
                             __global float* pierced_t, __global int* lists, __local int* group_counts) {
  const int r = get_global_id(0), lid = get_local_id(0);
  // No return before the barrier: every work-item of the group reaches it.
  const int count = r < n ? pvs_cast_ray(h, width, height, pyramid, levels, top, rays, n, line_major,
                                         curvature, cell_x, cell_y, view, view_x, band_lo, band_hi, cap,
                                         hit_t, hit_cell, pierced, pierced_t, r)
                          : 0;
  group_counts[lid] = count;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (r >= n) return;
  counts[r] = count;
  int before = 0;
  for (int i = 0; i < lid; ++i) before += group_counts[i];
  __global int* out = lists + 2 * ((size_t)get_group_id(0) * get_local_size(0) * cap + (size_t)before);
  const size_t list = line_major ? (size_t)r * cap : (size_t)r;
  const size_t stride = line_major ? 1 : (size_t)n;
  for (int j = 0; j < count; ++j) {
    out[2 * j] = pierced[list + j * stride];
    out[2 * j + 1] = as_int(pierced_t[list + j * stride]);
  }
}
