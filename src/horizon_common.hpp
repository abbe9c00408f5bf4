// horizon_common.hpp: what the device path and the scalar reference of the horizon
// operation share: direction geometry and the final reduction step.
#pragma once

#include <vector>

#include "hfvis/horizon.hpp"
#include "lattice_geometry.hpp"
#include "sweep_geometry.hpp"

namespace hfvis::detail {

// The sweep directions of a run: exact azimuths (within options.azimuth_tolerance) when
// per-direction planes are requested, quadrature directions otherwise.
std::vector<LatticeDirection> horizonDirections(const HeightField& field, const HorizonOptions& options,
                                                const HorizonOutputs& outputs);

// sin(pi weight) / pi: the factor of the ambient-occlusion swath of a direction of that
// weight (ambient_term in kernels/horizon.cl), computed once per direction on the host.
float swathFactor(float weight);

// Turns the accumulated sums into the outputs: svf = 1 - weighted sum; ao is the sum itself.
void finishReduction(HorizonResult& result);

// Whether the field has per-row spacing (HeightField::row_cell_size_x/y): positions along the
// sweep's lines and the naive march's rays are then ground lengths summed step by step.
bool hasRowSpacing(const HeightField& field);

// Throws InvalidArgument for what the horizon operation does not do on this field: a maximum
// distance with per-row spacing.
void requireSupported(const HeightField& field, const HorizonOptions& options);

// An empty result with the requested planes allocated (NaN-filled).
HorizonResult allocateResult(const HeightField& field, const HorizonOptions& options,
                             const HorizonOutputs& outputs);

}  // namespace hfvis::detail
