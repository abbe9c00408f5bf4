// direction_terms.cl: what one direction of the horizon operation contributes at a receiver:
// its elevation, and the sky-view (sky_view_factor.cl) and ambient-occlusion
// (ambient_occlusion.cl) terms, as one macro that defines them for a scalar or lane-vector
// type. Written once in the common subset of OpenCL C and C++: kernels/horizon.cl instantiates
// it for floats and lane vectors, src/core/direction_terms.hpp for the C++ references' floats.
#ifndef HFVIS_DIRECTION_TERMS_CL
#define HFVIS_DIRECTION_TERMS_CL

#include "ambient_occlusion.cl"
#include "fast_math.cl"
#include "sky_view_factor.cl"

// What one direction contributes at a receiver whose horizon has slope rise / run (run > 0;
// found 0 when no point casts one: elevation -pi/2), for scalars and lane vectors alike.
#define HFVIS_DIRECTION_TERMS(T, IT)                                                             \
  HFVIS_INLINE HFVIS_OVERLOADABLE T elevation_term(IT found, T rise, T run) {                    \
    return found ? hf_atan(rise / run) : (T)(-0.5f * HFVIS_PI_F);                                \
  }                                                                                              \
  HFVIS_SKY_VIEW_FACTOR_TERM(T, IT)                                                              \
  HFVIS_AMBIENT_OCCLUSION_TERM(T, IT)

#endif  // HFVIS_DIRECTION_TERMS_CL
