// fast_math.cl: the few transcendental functions the reductions need, as straight-line
// polynomials. Library atan2/sin calls are not vectorised by PoCL and cost ~100 ns each
// there; these vectorise. Written once in the common subset of OpenCL C and C++: the
// kernels include it, and so does src/core/fast_math.hpp (inside namespace hfvis::detail, with
// fabs and rint from <cmath>), so the scalar references round exactly as the kernels do.
// Accuracy: |error| < 2e-7 rad for hf_atan, < 1e-7 for hf_sin on |x| <= 2 pi (measured by
// tests/test_fast_math.cpp).
#ifndef HFVIS_FAST_MATH_CL
#define HFVIS_FAST_MATH_CL

#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline __attribute__((always_inline))
#endif
#define HFVIS_OVERLOADABLE __attribute__((overloadable))  // hf_atan for floats and lane vectors
#else  // C++: header functions, built with -ffp-contract=off; overloading is the language's
#ifndef HFVIS_INLINE
#define HFVIS_INLINE inline
#endif
#define HFVIS_OVERLOADABLE
#endif

#define HFVIS_PI_F 3.14159265358979323846f

// min and max of two numbers (not NaN): PoCL 3.1 compiles fmin/fmax in scalar code to a
// library call that made the hull tree's safe zone 50 % slower; a compare and select
// is one instruction on every device.
HFVIS_INLINE float hf_min(float a, float b) { return a < b ? a : b; }
HFVIS_INLINE float hf_max(float a, float b) { return a > b ? a : b; }

// atan(x) for any x (+-inf gives +-pi/2): Cephes' atanf range reduction to
// |x| <= tan(pi/8) and its degree-9 odd polynomial. Defined for float and, through
// HFVIS_DEFINE_ATAN, for the vector types a kernel needs (the same operations lane by lane).
#define HFVIS_DEFINE_ATAN(T, IT)                                                                             \
  HFVIS_INLINE HFVIS_OVERLOADABLE T hf_atan(T x) {                                                \
    T a = fabs(x);                                                                                           \
    IT big = a > 2.414213562373095f;  /* tan(3 pi / 8) */                                                    \
    IT mid = a > 0.4142135623730950f; /* tan(pi / 8) */                                                      \
    T reduced = big ? -1.0f / a : (mid ? (a - 1.0f) / (a + 1.0f) : a);                                       \
    T base = big ? (T)(0.5f * HFVIS_PI_F) : (mid ? (T)(0.25f * HFVIS_PI_F) : (T)0.0f);                       \
    T z = reduced * reduced;                                                                                 \
    T p =                                                                                                    \
        (((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z; \
    T y = base + (p * reduced + reduced);                                                                    \
    return x < 0.0f ? -y : y;                                                                                \
  }
HFVIS_DEFINE_ATAN(float, int)

// sin(x) for |x| <= 2 pi: reduced to [-pi/2, pi/2], then Taylor to x^11.
HFVIS_INLINE float hf_sin(float x) {
  float r = x - 2.0f * HFVIS_PI_F * rint(x * (0.5f / HFVIS_PI_F));
  r = r > 0.5f * HFVIS_PI_F ? HFVIS_PI_F - r : r;
  r = r < -0.5f * HFVIS_PI_F ? -HFVIS_PI_F - r : r;
  float z = r * r;
  float p =
      ((((-2.5052108385e-8f * z + 2.7557319224e-6f) * z - 1.9841269841e-4f) * z + 8.3333333333e-3f) * z -
       1.6666666667e-1f) *
      z;
  return p * r + r;
}

#endif  // HFVIS_FAST_MATH_CL
