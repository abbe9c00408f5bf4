// hfvis_testing/sky_view_factor_reference.hpp: the scalar reference of the sky-view factor
// (hfvis/sky_view_factor.hpp): the horizon references (horizon_reference.hpp) with this output
// alone, summing the kernels' own per-direction term (kernels/shared/sky_view_factor.cl).
// Test support library hfvis_testing; not installed.
#pragma once

#include "hfvis/sky_view_factor.hpp"

namespace hfvis {

SkyViewFactorResult referenceSkyViewFactor(const HeightField& field, const HorizonOptions& options);

}  // namespace hfvis
