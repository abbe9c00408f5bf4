// hfvis/bounce.hpp: one diffuse light bounce on a height field: from a given exit radiance
// per surface point, the incident indirect irradiance at every pixel, gathered over the
// visible segments of each sweep line (Timonen 2013, Sec. 10.1, alternative 3: step through
// the visible samples, and the surface's peaks between them, of each visibility horizon's
// segment).
//
// The formula. Receiver p has the unit normal n of the four quads around its pixel (in
// ground units, as ambient occlusion uses). Direction k stands for an azimuthal wedge of
// width D around it (about 2*pi/K; see below). In the vertical plane of direction k, the visible samples x
// at ground distance r_x and height difference dz_x are seen at elevations
// theta_x = atan2(dz_x, r_x), which never decrease outward but within the heights' rounding
// (visibility, tie rule as in hfvis/intervisibility.hpp: a sample hidden only within it is seen).
// So are the visible peaks: the surface's highest point between two samples where it rises above
// their chord (the tree's peaks, hfvis/intervisibility.hpp; seen exactly, never by the tie rule),
// with the exit radiance between its two samples', weighted as its position lies between them.
// Together the visible nodes (samples and peaks) cover the elevations from the receiver's tangent
// elevation (theta_t below) to the farthest one's, split into one band per visible node:
//   - between two visible nodes with no hidden sample between them (the surface piece
//     between them is visible) at the mean of their two elevations;
//   - across hidden samples (between a segment's horizon and the nearest visible node of
//     the next farther segment) the whole band goes to the farther node: what shows there
//     is the surface rising toward it;
//   - below the nearest visible node, down to theta_t, the band goes to that node: what shows
//     there is the surface between the receiver and it (a pit's walls, a wall beside the
//     receiver; when it ended at the nearest node's elevation, a pixel whose nearest sample
//     was its horizon gathered nothing). At the floor of a pit of one pixel the rim of its own
//     cells, a peak, hides every sample off the axes: until peaks carried radiance, nothing was
//     gathered there in those directions (E / (pi L) + AO was 0.07 instead of 1).
// A band [a, b] of sample x adds L_x * (G(b) - G(a)), where
//   G(theta) = n_z * (D/2) * sin^2(theta) + (n . d_k) * 2 sin(D/2) * (theta + sin(theta) cos(theta)) / 2
// is the exact integral over the wedge of the projected solid angle (n . w) dw up to
// elevation theta (the same integral as ambient occlusion's Eq. 5), with theta clipped from
// below at theta_t = atan2(-(n . d_k) * 2 sin(D/2), n_z * D), where the wedge's cosine factor
// changes sign: surface behind the receiver's tangent plane adds nothing, and every band
// adds a non-negative amount. The irradiance is E = sum_k sum_x L_x (G_k(hi_x) - G_k(lo_x)).
// A uniform radiance L gives L * (G(theta_farthest) - G(theta_t)) per direction (the bands
// telescope); a flat plane gives 0 (every band is empty); and since the sky above the horizon is
// what ambient occlusion integrates with the same G, E / (pi L) + AO is about 1 (at most).
//
// Units: E is in radiance units times steradians (W/m^2 for W m^-2 sr^-1). A Lambertian
// surface of albedo rho re-emits rho * E / pi, which can feed the next bounce.
//
// Per-pixel values, as the visible counts: every pixel is the receiver of its own lattice
// line in each direction (hfvis/intervisibility.hpp), gathering with its own normal over the
// visible samples of its own ray, whose exit radiance is sampled bilinearly like their
// heights. Direction k's wedge D is 2 pi times the quadrature weight of its lattice step
// (about 2 pi / K; the steps and weights of hfvis/intervisibility.hpp). Nodata pixels
// receive NaN and emit nothing.
#pragma once

#include <string>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis {

// Exit radiance channels gathered in one run (one tree sweep serves all of them).
constexpr int kMaxBounceChannels = 4;

struct BounceOptions : SweepOptions {
  HullTreeTuning tree;  // how the tree sweep works; never changes the result
};

// Exit radiance per pixel of the height field: 1..kMaxBounceChannels planes (grey, RGB,
// ...), each width*height, finite, >= 0 and at most 1e30 at every pixel whose height is valid
// (values at nodata pixels are ignored).
struct ExitRadiance {
  int width = 0;
  int height = 0;
  std::vector<std::vector<float>> channels;
};

struct BounceResult {
  int width = 0;
  int height = 0;
  int directions = 0;
  std::vector<double> azimuths;                // phi_k, radians
  std::vector<std::vector<float>> irradiance;  // one plane per radiance channel; NaN at nodata
};

// Throws InvalidArgument for bad sweep options (see sweep_options.hpp) or tree tuning.
void validate(const BounceOptions& options);

// Throws InvalidArgument when the radiance does not fit the field (size, 1..4 channels,
// plane sizes) or is not finite and >= 0 at a pixel with a valid height (names the pixel).
void validate(const HeightField& field, const ExitRadiance& radiance);

// Tree sweep with the gather, and the reduction, on the device of `context`. Throws
// InvalidArgument, MemoryBudgetError, OpenClError, KernelBuildError.
BounceResult computeBounce(const ComputeContext& context, const HeightField& field,
                           const ExitRadiance& radiance, const BounceOptions& options);

}  // namespace hfvis
