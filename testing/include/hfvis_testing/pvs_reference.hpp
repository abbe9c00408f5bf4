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
// in double precision; INFINITY when there is none. `curvature`: RayCastOptions::curvature.
double bruteForceRayHit(const HeightField& field, const HeightRay& ray, double step, double curvature = 0.0);

// The ray's height above the surface at t, in double precision (NaN outside the box or over a
// cell with a nodata corner); with curvature c the ray's height is oz + t dz + c g^2 t^2, g its
// ground length per unit of t (RayCastOptions::curvature).
double rayClearance(const HeightField& field, const HeightRay& ray, double t, double curvature = 0.0);

// Random rays from the view band (uniform over the valid cells' squares, at H0 .. H1 above the
// surface) in uniform directions (ground units), unbounded; a seed gives the same rays.
std::vector<HeightRay> randomViewRays(const HeightField& f, const PvsGrid& grid, int count,
                                      std::uint32_t seed);

// The measured pixel error (Bittner et al. 2009, Sec. 4.5's definition): of the view rays `rays`
// (hit by castHeightFieldRays as `hits`), those whose hit tile is missing from the PVS of the
// view cell they start in, per `resolution` rays.
double measuredPixelError(const HeightField& f, const PvsResult& pvs, const std::vector<HeightRay>& rays,
                          const RayCastResult& hits, double resolution);

}  // namespace hfvis
