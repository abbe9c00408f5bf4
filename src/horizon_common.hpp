// horizon_common.hpp: what the device path and the scalar reference of the horizon
// operation share: height preparation, direction geometry and the final reduction step.
#pragma once

#include <vector>

#include "hfvis/horizon.hpp"
#include "lattice_geometry.hpp"
#include "sweep_geometry.hpp"

namespace hfvis::detail {

// Heights as the kernels see them: (h - lowest finite height) * z_scale in float, so that
// a plane at 8848 m keeps its millimetres; every non-finite height becomes NaN. Throws
// InvalidArgument when a prepared height would exceed kMaxPreparedHeight: the kernels
// multiply height differences by distances (up to 2^31 pixels) in float, which must stay
// finite.
constexpr double kMaxPreparedHeight = 1e28;
struct PreparedHeights {
  std::vector<float> heights;
  bool has_nodata = false;
};
PreparedHeights prepareHeights(const HeightField& field);

// The sweep directions of a run: exact azimuths (within options.azimuth_tolerance) when
// per-direction planes are requested, quadrature directions otherwise.
std::vector<LatticeDirection> horizonDirections(const HeightField& field, const HorizonOptions& options,
                                                const HorizonOutputs& outputs);

// sin(pi weight) / pi: the factor of the ambient-occlusion swath of a direction of that
// weight (ambient_term in kernels/horizon.cl), computed once per direction on the host.
float swathFactor(float weight);

// Turns the accumulated sums into the outputs: svf = 1 - weighted sum; ao is the sum itself.
void finishReduction(HorizonResult& result);

// An empty result with the requested planes allocated (NaN-filled).
HorizonResult allocateResult(const HeightField& field, const HorizonOptions& options,
                             const HorizonOutputs& outputs);

}  // namespace hfvis::detail
