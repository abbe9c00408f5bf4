// lanes.cl: SIMD lanes of a work-item (compile-time HFVIS_LANES, 1 or 8). On a CPU one
// work-item can run 8 lines or rays side by side, one per lane, in lock step: data-dependent
// branches become masked vector steps (horizon.cl's sweep, viewshed.cl's rays, the hull tree's
// peaks prepass in intervisibility.cl); on GPUs each work-item runs one (HFVIS_LANES 1).
#ifndef HFVIS_LANES_CL
#define HFVIS_LANES_CL

#include "fast_math.cl"

// LANE(v, l) is lane l of v; LANES_FROM(f) (ILANES_FROM) the lanes f(0), f(1), ... of a float (int)
// vector, for f a macro of the lane (built whole: a vector written lane by lane through LANE
// waits on its stores when read whole); comparisons give -1 in a vector lane and 1 in a scalar, so
// masks come only from comparisons, !, & and |, are tested for nonzero, and choose through
// select() or ?: (both take -1 / 0 lanes and 1 / 0 scalars alike). any() compiles to a test
// and branch per lane; any_lane packs the lanes' masks into one 64-bit word.
#ifndef HFVIS_LANES
#define HFVIS_LANES 1
#endif
#if HFVIS_LANES == 1
typedef float lane_float;
typedef int lane_int;
#define LANE(v, l) (v)
#define ILANE(v, l) (v)
#define ANY_LANE(m) ((m) != 0)
#define LANE_FLOAT(v) ((float)(v))
#define LANE_INT(v) ((int)(v))
#define LANES_FROM(f) ((float)(f(0)))
#define ILANES_FROM(f) ((int)(f(0)))
#elif HFVIS_LANES == 8
typedef float8 lane_float;
typedef int8 lane_int;
#define LANE(v, l) (((__private float*)&(v))[l])
#define ILANE(v, l) (((__private int*)&(v))[l])
HFVIS_INLINE int any_lane(int8 m) { return as_ulong(convert_char8(m)) != 0; }
#define ANY_LANE(m) any_lane(m)
#define LANE_FLOAT(v) convert_float8(v)
#define LANE_INT(v) convert_int8(v)
#define LANES_FROM(f) ((float8)(f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)))
#define ILANES_FROM(f) ((int8)(f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7)))
#else
#error "HFVIS_LANES must be 1 or 8"
#endif

#endif
