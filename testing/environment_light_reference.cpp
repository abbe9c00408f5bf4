// environment_light_reference.cpp: see hfvis_testing/environment_light_reference.hpp.
#include "hfvis_testing/environment_light_reference.hpp"

#include <utility>

#include "hfvis_testing/horizon_reference.hpp"

namespace hfvis {

EnvironmentLightResult referenceEnvironmentLight(const HeightField& field, const EnvironmentMap& map,
                                                 const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.environment = &map;
  HorizonResult horizons = referenceHorizons(field, options, outputs);
  return {horizons.width, horizons.height, horizons.directions, map.names, std::move(horizons.irradiance)};
}

}  // namespace hfvis
