// ambient_occlusion.cpp: ambient occlusion (hfvis/ambient_occlusion.hpp): the horizon operation
// with this output alone, so the sweep stores no plane and reduces each direction's swath
// (kernels/shared/ambient_occlusion.cl) straight into one sum per pixel.
#include "hfvis/ambient_occlusion.hpp"

#include <utility>

namespace hfvis {

AmbientOcclusionResult computeAmbientOcclusion(const ComputeContext& context, const HeightField& field,
                                               const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.ambient_occlusion = true;
  HorizonResult horizons = computeHorizons(context, field, options, outputs);
  return {horizons.width,
          horizons.height,
          horizons.directions,
          std::move(horizons.ambient_occlusion),
          std::move(horizons.error_estimate),
          horizons.estimated_error};
}

}  // namespace hfvis
