// sky_view_factor_reference.cpp: see hfvis_testing/sky_view_factor_reference.hpp.
#include "hfvis_testing/sky_view_factor_reference.hpp"

#include <utility>

#include "hfvis_testing/horizon_reference.hpp"

namespace hfvis {

SkyViewFactorResult referenceSkyViewFactor(const HeightField& field, const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  HorizonResult horizons = referenceHorizons(field, options, outputs);
  return {horizons.width, horizons.height, horizons.directions, std::move(horizons.sky_view_factor), {}, 0.0};
}

}  // namespace hfvis
