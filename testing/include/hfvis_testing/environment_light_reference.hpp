// hfvis_testing/environment_light_reference.hpp: the scalar reference of environment light
// (hfvis/environment_light.hpp): the horizon references (horizon_reference.hpp) with this output
// alone, its tables built on their own in double and evaluated by the kernels' own code
// (kernels/environment_light.cl). Test support library hfvis_testing; not installed.
#pragma once

#include "hfvis/environment_light.hpp"

namespace hfvis {

EnvironmentLightResult referenceEnvironmentLight(const HeightField& field, const EnvironmentMap& map,
                                                 const HorizonOptions& options);

}  // namespace hfvis
