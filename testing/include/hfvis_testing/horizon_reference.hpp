// hfvis_testing/horizon_reference.hpp: scalar C++ references of the horizon kernels. Same algorithm, same
// sample points, same predicates and operation order as the OpenCL kernels, one pixel or
// line at a time on the host: the oracles of the tests and the baselines of the benchmark
// (test support library hfvis_testing; not installed).
#pragma once

#include "hfvis/horizon.hpp"

namespace hfvis {

// options.method chooses the reference: the lattice hull-stack sweep with its per-receiver
// outputs, or the naive per-pixel march. progress and memory_budget_bytes are ignored.
HorizonResult referenceHorizons(const HeightField& field, const HorizonOptions& options,
                                const HorizonOutputs& outputs);

}  // namespace hfvis
