// sun_shading_reference.cpp: see hfvis_testing/sun_shading_reference.hpp.
#include "hfvis_testing/sun_shading_reference.hpp"

#include "hfvis_testing/horizon_reference.hpp"
#include "ops/sun_shading_pixels.hpp"

namespace hfvis {

SunShadingResult referenceSunShading(const HeightField& field, const SunLight& sun, const SweepOptions& options) {
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  const HorizonResult horizons = referenceHorizons(field, detail::sunSweep(sun, options), outputs);
  return detail::sunShadingFromHorizons(field, sun, horizons.angles, horizons.azimuths.at(0));
}

}  // namespace hfvis
