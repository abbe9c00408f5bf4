// hfvis_testing/ambient_occlusion_reference.hpp: the scalar reference of ambient occlusion
// (hfvis/ambient_occlusion.hpp): the horizon references (horizon_reference.hpp) with this
// output alone, summing the kernels' own per-swath term (kernels/shared/ambient_occlusion.cl).
// Test support library hfvis_testing; not installed.
#pragma once

#include "hfvis/ambient_occlusion.hpp"

namespace hfvis {

AmbientOcclusionResult referenceAmbientOcclusion(const HeightField& field, const HorizonOptions& options);

}  // namespace hfvis
