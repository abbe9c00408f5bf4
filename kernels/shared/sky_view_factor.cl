// sky_view_factor.cl: one direction's term of the sky-view factor (hfvis/sky_view_factor.hpp),
// as a macro that defines it for a scalar or lane-vector type. Written in the common subset of
// OpenCL C and C++: kernels/horizon.cl and the C++ references (src/core/direction_terms.hpp)
// instantiate it through HFVIS_DIRECTION_TERMS (direction_terms.cl).
//
// The sky-view factor is 1 - sum_k w_k sin(max(0, e_k)) over the directions' horizon
// elevations e_k (Zaksek, Ostir & Kokalj 2011). For a horizon of slope rise / run (run > 0;
// found 0 when no point casts one) the term sin(max(0, e)) is rise / sqrt(rise^2 + run^2) for
// a rising horizon and 0 otherwise, so the angle itself is never computed.
#ifndef HFVIS_SKY_VIEW_FACTOR_CL
#define HFVIS_SKY_VIEW_FACTOR_CL

#define HFVIS_SKY_VIEW_FACTOR_TERM(T, IT)                                                        \
  HFVIS_INLINE HFVIS_OVERLOADABLE T sky_term(IT found, T rise, T run) {                          \
    return (found & (rise > 0.0f)) ? rise / sqrt(rise * rise + run * run) : (T)0.0f;             \
  }

#endif  // HFVIS_SKY_VIEW_FACTOR_CL
