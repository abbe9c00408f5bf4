// hfvis_testing/pvs_reference.hpp: the height-field ray caster of the potentially visible sets on
// the host, ray by ray: the same code as the kernel (kernels/shared/heightfield_ray.cl, compiled
// here as C++), so the two agree bit for bit; and a brute-force march of the same surface in
// double precision, independent of both (test support library hfvis_testing; not installed).
#pragma once

#include <vector>

#include "hfvis/pvs.hpp"

namespace hfvis {

// castHeightFieldRays, scalar. Throws as it does (but for the device's errors).
RayCastResult referenceCastHeightFieldRays(const HeightField& field, const std::vector<HeightRay>& rays,
                                           const RayCastOptions& options = {});

// The first sample t = (k + 1/2) step (k = 0, 1, ...) of the ray inside the field's box and within t_max
// where the ray lies strictly below the bilinear surface (cells with a nodata corner have none),
// in double precision; INFINITY when there is none.
double bruteForceRayHit(const HeightField& field, const HeightRay& ray, double step);

// The ray's height above the surface at t, in double precision (NaN outside the box or over a
// cell with a nodata corner).
double rayClearance(const HeightField& field, const HeightRay& ray, double t);

}  // namespace hfvis
