// environment_light.cpp: the irradiance from an HDR environment (hfvis/environment_light.hpp):
// the horizon operation with this output alone (its tables: src/core/environment_swaths.hpp).
#include "hfvis/environment_light.hpp"

#include <utility>

namespace hfvis {

EnvironmentLightResult computeEnvironmentLight(const ComputeContext& context, const HeightField& field,
                                               const EnvironmentMap& map, const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.environment = &map;
  HorizonResult horizons = computeHorizons(context, field, options, outputs);
  return {horizons.width, horizons.height, horizons.directions, map.names, std::move(horizons.irradiance)};
}

}  // namespace hfvis
