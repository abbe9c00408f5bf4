// hfvis_testing/intervisibility_reference.hpp: scalar C++ references of the intervisibility
// kernels: the same convex hull tree, the same samples, the same exact predicate, one line
// or pixel at a time on the host. The oracles of the tests and baselines of the benchmark
// (test support library hfvis_testing; not installed).
#pragma once

#include "hfvis/intervisibility.hpp"

namespace hfvis {

// options.method chooses the reference: the hull-tree sweep with its reduction, or the
// naive per-pixel march. progress and memory_budget_bytes are ignored. Per-line results
// equal the kernels' exactly; per-pixel sums may differ in the last bits (the kernels sum
// a batch of directions before adding it). outputs.error_estimate is computed as the device
// path computes it; options.max_error is not taken (the reference runs the K given).
IntervisibilityResult referenceIntervisibility(const HeightField& field,
                                               const IntervisibilityOptions& options,
                                               const IntervisibilityOutputs& outputs);

// The error the count's estimate stands for: per pixel |count / K - truth's count / its K| (each
// run's count sums its K directions), relative to the truth's mean over the field (NaN at
// nodata); its 99th percentile over the pixels with data, the percentile
// IntervisibilityResult::estimated_error takes of the estimate. `truth`: a dense run.
double countErrorP99(const IntervisibilityResult& result, const IntervisibilityResult& truth);

}  // namespace hfvis
