// hfvis_testing/sun_shading_reference.hpp: the scalar reference of sun shading
// (hfvis/sun_shading.hpp): the sun's azimuth swept by the horizon reference, then the library's
// own per-pixel step (src/ops/sun_shading_pixels.hpp). Test support library hfvis_testing; not
// installed.
#pragma once

#include "hfvis/sun_shading.hpp"

namespace hfvis {

SunShadingResult referenceSunShading(const HeightField& field, const SunLight& sun, const SweepOptions& options = {});

}  // namespace hfvis
