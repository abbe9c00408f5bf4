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
  EnvironmentLightResult out;
  out.width = horizons.width;
  out.height = horizons.height;
  out.directions = horizons.directions;
  out.names = map.names;
  out.irradiance = std::move(horizons.irradiance);
  return out;
}

}  // namespace hfvis
