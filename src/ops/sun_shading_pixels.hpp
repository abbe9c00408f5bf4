// sun_shading_pixels.hpp: the two halves of sun shading (hfvis/sun_shading.hpp): the sweep of
// the sun's azimuth, and per pixel the sun's disc above its horizon there and the direct
// irradiance it brings. Shared by computeSunShading (horizons from the device) and its scalar reference
// (testing/sun_shading_reference.cpp, horizons from the horizon reference).
#pragma once

#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/sun_shading.hpp"

namespace hfvis::detail {

// The one-direction horizon sweep of the sun's azimuth, with `options`' sampling, curvature,
// distance and budget.
HorizonOptions sunSweep(const SunLight& sun, const SweepOptions& options);

// angles: the horizon elevation of every pixel in the swept direction (NaN at nodata);
// azimuth: that direction's hfvis azimuth, radians.
SunShadingResult sunShadingFromHorizons(const HeightField& field, const SunLight& sun, const std::vector<float>& angles,
                                        double azimuth);

}  // namespace hfvis::detail
