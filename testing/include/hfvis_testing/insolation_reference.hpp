// hfvis_testing/insolation_reference.hpp: the scalar reference of insolation
// (hfvis/insolation.hpp): the same steps and buckets (src/ops/insolation_steps.hpp), each
// bucket's horizons from the horizon reference, and the kernel insolation_add
// (kernels/insolation.cl) mirrored in float on the host. Test support library hfvis_testing;
// not installed.
#pragma once

#include "hfvis/insolation.hpp"

namespace hfvis {

InsolationResult referenceInsolation(const HeightField& field, const InsolationOptions& options,
                                     const SweepOptions& sweep = {});

}  // namespace hfvis
