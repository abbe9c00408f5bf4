// hfvis/environment_light.hpp: the irradiance an HDR environment (hfvis/environment_map.hpp)
// gives a height field through its horizons (Timonen & Westerholm 2010, Sec. 6.2).
//
// The irradiance at a point with unit normal N is E = integral of L(w) max(0, N . w) over the
// directions w above its horizons: pi on open flat ground under a uniform environment of
// radiance 1 (and pi times the ambient occlusion of hfvis/horizon.hpp everywhere).
//
// How it is evaluated: per azimuthal direction k of the sweep (its swath of azimuth), N . w is
// N_z cos(theta) + sin(theta) (t cos(d) + p sin(d)) with theta the zenith angle, d the azimuth
// from the direction's own, and t, p the normal's components along the direction and across
// it. Eq. 7's table L_p(theta_n, theta_h) is then linear in (N_z, t, p): the swath's integral
// from the zenith down to a lower limit theta_h is N_z A_k(theta_h) + t B_k(theta_h) +
// p C_k(theta_h), with A, B, C integrals of the environment over the swath (exactly, column by
// column) and over zenith angle, weighted by cos(theta) sin(theta) and sin^2(theta). So the
// table needs no normal-angle axis: where the paper interpolates between normal angles, hfvis
// is exact for every normal, and the lower limit is the horizon or the tangent plane's cut
// (N . w = 0 in the direction's azimuth), whichever is higher, as for ambient occlusion. The
// tables have one entry per band of zenith angle (table_rows bands); within a band the
// radiance is the band's mean, and the zenith integral is exact, so with the map's own rows
// (the default) the only approximation is the sweep's: the horizon is taken as constant over
// each swath, and the tangent plane's cut at the direction's azimuth.
#pragma once

#include <string>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/environment_map.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis {

struct EnvironmentLightResult {
  int width = 0;
  int height = 0;
  int directions = 0;               // K: as given, or as options.max_error chose it
  std::vector<std::string> names;   // the map's channels: {"Y"} or {"R", "G", "B"}
  std::vector<float> irradiance;    // one plane of width * height per channel; NaN at nodata
  // With options.max_error, per pixel: the larger of |the irradiance at K - the irradiance at
  // K / 2| on K's even directions and on its odd ones (a run at K / 2 turned by one step of K),
  // relative to the field's mean irradiance, the largest over the channels; NaN at nodata. Not
  // the even and odd halves of one run, as for the sky-view factor: each direction integrates the
  // environment over its own swath of azimuth, so two halves would differ by the environment's own
  // azimuthal structure, which no error of the result has. Both coarse runs, because a sun lights
  // a pixel through the one direction whose swath holds it: where that direction at K is one of
  // the even ones, the even run puts every shadow where K's does and misses their misplacement.
  std::vector<float> error_estimate;
  double estimated_error = 0.0;  // its 99th percentile over the pixels with data
  std::vector<int> runs;         // with options.max_error: the K of each run (each also ran twice at K / 2)
};

// The horizon operation with this output alone (computeHorizons with
// HorizonOutputs::environment = &map), on the device of `context`. Throws what computeHorizons
// throws (a bad map, a latitude / longitude grid).
// options.max_error (0 < E < 1, relative): K is chosen as IntervisibilityOptions::max_error
// chooses it (options.directions ignored), so that the 99th percentile of the estimate above
// (EnvironmentLightResult::estimated_error) is at most E; every run is made at K and twice at
// K / 2. Throws InvalidArgument for E outside (0, 1) and, naming the K it would take, where
// IntervisibilityOptions::max_error does.
EnvironmentLightResult computeEnvironmentLight(const ComputeContext& context, const HeightField& field,
                                               const EnvironmentMap& map, const HorizonOptions& options = {});

}  // namespace hfvis
