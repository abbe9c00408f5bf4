// hfvis_testing/region_visibility_reference.hpp: region visibility on the host, one pair at a
// time: the same sample positions and the same line-of-sight test as the kernel
// (kernels/shared/region_visibility_sight.cl, compiled here as C++), so the two agree bit for bit; the
// oracle of the region visibility tests (test support library hfvis_testing; not installed).
#pragma once

#include "hfvis/region_visibility.hpp"

namespace hfvis {

// computeRegionVisibility, scalar. Throws as it does (but for the device's errors).
RegionVisibilityResult referenceRegionVisibility(const HeightField& field, const RegionSampling& sources,
                                                 const RegionVisibilityOptions& options);

// computeRegionPairVisibility, scalar.
RegionPairVisibilityResult referenceRegionPairVisibility(const HeightField& field,
                                                         const RegionSampling& sources,
                                                         const RegionSampling& receivers,
                                                         const RegionVisibilityOptions& options);

}  // namespace hfvis
