// environment_light_reference.cpp: see hfvis_testing/environment_light_reference.hpp.
#include "hfvis_testing/environment_light_reference.hpp"

#include "hfvis_testing/horizon_reference.hpp"
#include "ops/environment_light_result.hpp"

namespace hfvis {

EnvironmentLightResult referenceEnvironmentLight(const HeightField& field, const EnvironmentMap& map,
                                                 const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.environment = &map;
  return detail::environmentLightResult(referenceHorizons(field, options, outputs), map);
}

}  // namespace hfvis
