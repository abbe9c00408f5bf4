// hfvis/ambient_occlusion.hpp: ambient occlusion (AO): the irradiance a point of the surface
// receives from a uniform sky of radiance 1 through its horizons, normalised so that open flat
// ground gets 1 (Eq. 5 of Timonen & Westerholm 2010): per azimuthal swath of the K directions
// (hfvis/sweep_options.hpp), the cosine-weighted sky between the zenith and the higher of the
// horizon and the tangent plane, for the pixel's own normal. A tilted plane with nothing above
// it gets 1; the sky-view factor (hfvis/sky_view_factor.hpp) counts sky, not light, and gives a
// tilted plane less.
//
// The horizon sweep (hfvis/horizon.hpp) computes it with nothing else stored; heman's
// ambient occlusion answers the same question by the same paper's method.
#pragma once

#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis {

struct AmbientOcclusionResult {
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
AmbientOcclusionResult computeAmbientOcclusion(const ComputeContext& context, const HeightField& field,
                                               const HorizonOptions& options = {});

}  // namespace hfvis
