// horizon_common.hpp: what the device path and the scalar reference of the horizon
// operation share: height preparation, direction geometry and the final reduction step.
#pragma once

#include <vector>

#include "hfvis/horizon.hpp"
#include "sweep_geometry.hpp"

namespace hfvis::detail {

// Heights as the kernels see them: (h - lowest finite height) * z_scale in float, so that
// a plane at 8848 m keeps its millimetres; every non-finite height becomes NaN.
struct PreparedHeights {
  std::vector<float> heights;
  bool has_nodata = false;
};
PreparedHeights prepareHeights(const HeightField& field);

// Turns the accumulated sums into the outputs: svf = 1 - sum / K; ao is the sum itself.
void finishReduction(const HorizonOptions& options, HorizonResult& result);

// An empty result with the requested planes allocated (NaN-filled).
HorizonResult allocateResult(const HeightField& field, const HorizonOptions& options,
                             const HorizonOutputs& outputs);

}  // namespace hfvis::detail
