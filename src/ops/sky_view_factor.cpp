// sky_view_factor.cpp: the sky-view factor (hfvis/sky_view_factor.hpp): the horizon operation
// with this output alone, so the sweep stores no plane and reduces each direction's
// sky term (kernels/shared/sky_view_factor.cl) straight into one sum per pixel.
#include "hfvis/sky_view_factor.hpp"

#include <utility>

namespace hfvis {

SkyViewFactorResult computeSkyViewFactor(const ComputeContext& context, const HeightField& field,
                                         const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  HorizonResult horizons = computeHorizons(context, field, options, outputs);
  return {horizons.width,
          horizons.height,
          horizons.directions,
          std::move(horizons.sky_view_factor),
          std::move(horizons.error_estimate),
          horizons.estimated_error};
}

}  // namespace hfvis
