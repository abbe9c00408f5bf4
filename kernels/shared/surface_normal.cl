// surface_normal.cl: the one pixel normal of hfvis, written once in the common subset of OpenCL C
// and C++: kernels/horizon.cl includes it (ambient occlusion, the environment), and so does
// src/core/surface_normal.hpp (inside namespace hfvis::detail, with isnan and clamp from the
// standard library) for the host's normals (sun shading, insolation, the bounce) and the scalar
// references, so they all run the very same operations.
#ifndef HFVIS_SURFACE_NORMAL_CL
#define HFVIS_SURFACE_NORMAL_CL

#ifdef __OPENCL_VERSION__
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline __attribute__((always_inline))
#endif
#define HFVIS_HEIGHTS __global const float*
#else  // C++: header functions, built with -ffp-contract=off
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline
#endif
#define HFVIS_HEIGHTS const float*
#endif

// The normal at pixel (c, r), the sum of the unnormalised normals of the (up to) four quads
// around it (Timonen & Westerholm 2010, Sec. 7) in ground units, into sum[0 .. 2] (x along
// +column, y along +row, z up; z counts the quads). Quads touching nodata or the border are
// left out (z = 0 when none is left). `heights` holds the field's rows from row0 on, h the
// pixel's own height.
HFVIS_INLINE void surface_normal_sum(HFVIS_HEIGHTS heights, int width, int height, int row0, int c, int r, float h,
                                     float cell_x, float cell_y, float* sum) {
  // Straight-line scalar code (clamped reads, masked sums) so that PoCL vectorises callers.
  float sx_sum = 0.0f, sy_sum = 0.0f, sz_sum = 0.0f;
  for (int q = 0; q < 4; ++q) {
    int sx = (q & 1) ? 1 : -1, sy = (q & 2) ? 1 : -1;
    int cx = c + sx, ry = r + sy;
    int inside = cx >= 0 && cx < width && ry >= 0 && ry < height;
    float hx = heights[(r - row0) * width + clamp(cx, 0, width - 1)];
    float hy = heights[(clamp(ry, 0, height - 1) - row0) * width + c];
    float gx = (hx - h) / ((float)sx * cell_x);
    float gy = (hy - h) / ((float)sy * cell_y);
    int use = inside && !isnan(hx) && !isnan(hy);
    sx_sum += use ? -gx : 0.0f;
    sy_sum += use ? -gy : 0.0f;
    sz_sum += use ? 1.0f : 0.0f;
  }
  sum[0] = sx_sum;
  sum[1] = sy_sum;
  sum[2] = sz_sum;
}

#endif  // HFVIS_SURFACE_NORMAL_CL
