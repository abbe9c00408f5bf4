// hfvis_testing/bounce_reference.hpp: the scalar C++ reference of computeBounce (test support; not
// installed).
#pragma once

#include "hfvis/bounce.hpp"

namespace hfvis {

// The scalar C++ reference of computeBounce (same samples, same visible sets, same bands;
// the kernels' transcendentals may differ in the last bits).
BounceResult referenceBounce(const HeightField& field, const ExitRadiance& radiance,
                             const BounceOptions& options);

}  // namespace hfvis
