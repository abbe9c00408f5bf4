// ambient_occlusion_reference.cpp: see hfvis_testing/ambient_occlusion_reference.hpp.
#include "hfvis_testing/ambient_occlusion_reference.hpp"

#include <utility>

#include "hfvis_testing/horizon_reference.hpp"

namespace hfvis {

AmbientOcclusionResult referenceAmbientOcclusion(const HeightField& field, const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.ambient_occlusion = true;
  HorizonResult horizons = referenceHorizons(field, options, outputs);
  return {horizons.width, horizons.height, horizons.directions, std::move(horizons.ambient_occlusion), {}, 0.0};
}

}  // namespace hfvis
