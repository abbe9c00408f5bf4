// ambient_occlusion.cl: one direction's term of ambient occlusion (hfvis/ambient_occlusion.hpp),
// as a macro that defines it for a scalar or lane-vector type. Written in the common subset of
// OpenCL C and C++: kernels/horizon.cl and the C++ references (src/core/direction_terms.hpp)
// instantiate it through HFVIS_DIRECTION_TERMS (direction_terms.cl); environment_light.cl takes
// the same lower limit.
//
// ambient_term: uniform-sky irradiance of one azimuthal swath (Eq. 5 of Timonen &
// Westerholm 2010) of width 2 pi * weight, normalised so that a flat plane sums to 1 over a
// run's swaths, at a receiver of unit normal (nx, ny, nz); linear in the normal (a multiple
// of it scales the term: x and `behind` are ratios). With elevation e and zenith
// angle z = pi/2 - e, Eq. 5's sin^2 z = cos^2 e = 1 / (1 + x^2) and sin 2z / 2 = x cos^2 e for
// x = tan e, so only e itself needs an arctangent. The sky behind the surface (N . e < 0)
// does not count: the horizon is at least the tangent plane's slope -toward / nz in this
// azimuth. swath = sin(pi weight) / pi, per direction.
// lower_limit: the slope tan(e) of that lowest elevation that counts, the horizon's or the
// tangent plane's, for the normal's component `toward` the direction and its nz.
#ifndef HFVIS_AMBIENT_OCCLUSION_CL
#define HFVIS_AMBIENT_OCCLUSION_CL

#include "fast_math.cl"

#define HFVIS_AMBIENT_OCCLUSION_TERM(T, IT)                                                      \
  HFVIS_INLINE HFVIS_OVERLOADABLE T lower_limit(IT found, T rise, T run, T toward, T nz) {       \
    IT behind = !found | (rise * nz < -toward * run);                                            \
    return behind ? -toward / nz : rise / run;                                                   \
  }                                                                                              \
  HFVIS_INLINE HFVIS_OVERLOADABLE T ambient_term(                                                \
      IT found, T rise, T run, T nx, T ny, T nz, T cos_az, T sin_az, T weight, T swath) {        \
    T toward = nx * cos_az + ny * sin_az;                                                        \
    T x = lower_limit(found, rise, run, toward, nz);                                             \
    T cos2 = 1.0f / (1.0f + x * x);                                                              \
    return nz * weight * cos2 + swath * (0.5f * HFVIS_PI_F - hf_atan(x) - x * cos2) * toward;    \
  }

#endif  // HFVIS_AMBIENT_OCCLUSION_CL
