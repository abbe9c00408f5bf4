// hfvis/sky_view_factor.hpp: the sky-view factor (SVF): the share of the sky a point of the
// surface sees above its horizons, 1 on open flat ground, less in valleys, streets and pits.
// The definition of Zaksek, Ostir & Kokalj (2011), as RVT and xarray-spatial compute it:
//
//   SVF = 1 - sum_k w_k sin(max(0, e_k))
//
// over K azimuthal directions (hfvis/sweep_options.hpp), e_k the horizon elevation in direction
// k and w_k the share of the circle it stands for (1 / K on the naive march's exact azimuths).
// The horizon sweep (Timonen & Westerholm 2010; hfvis/horizon.hpp) computes it with nothing
// else stored: the sweep takes the cheapest integer step within half the spacing 2 pi / K of
// each phi_k and weighs it by its swath (docs/ALGORITHMS.md). Unlike RVT's, the horizons have no
// radius limit unless options.max_distance sets one.
#pragma once

#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis {

struct SkyViewFactorResult {
  int width = 0;
  int height = 0;
  int directions = 0;         // K: as given, or as options.max_error chose it
  std::vector<float> values;  // width * height, 0 .. 1; NaN at nodata
  // With options.max_error: the per-pixel error estimate and its 99th percentile
  // (HorizonResult::error_estimate, ::estimated_error); else empty and 0.
  std::vector<float> error_estimate;
  double estimated_error = 0.0;
};

// Runs options.method (the sweep by default) on the device of `context`. Throws what
// computeHorizons throws.
SkyViewFactorResult computeSkyViewFactor(const ComputeContext& context, const HeightField& field,
                                         const HorizonOptions& options = {});

}  // namespace hfvis
