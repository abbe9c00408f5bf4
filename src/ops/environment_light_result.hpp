// environment_light_result.hpp: the environment light's result from a horizon run that computed its
// irradiance alone, for the library (src/ops/environment_light.cpp) and its scalar reference
// (testing/environment_light_reference.cpp), so both assemble it the same way.
#pragma once

#include <utility>

#include "hfvis/environment_light.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis::detail {

inline EnvironmentLightResult environmentLightResult(HorizonResult&& horizons, const EnvironmentMap& map) {
  EnvironmentLightResult result;
  result.width = horizons.width;
  result.height = horizons.height;
  result.directions = horizons.directions;
  result.names = map.names;
  result.irradiance = std::move(horizons.irradiance);
  return result;
}

}  // namespace hfvis::detail
