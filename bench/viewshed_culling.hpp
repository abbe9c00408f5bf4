// bench/viewshed_culling.hpp: what Stewart's culling pyramid (buildViewshedPyramid) costs and
// saves: its preprocessing time and memory per finest level kept, and per observer the share
// of the points it culls and the time of a culled viewshed against an exact one.
#pragma once

#include <string>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/viewshed.hpp"

namespace hfvis::bench {

// The pyramid without its levels finer than k (what building it with finest_level = k gives:
// a parent's regions are its children's intersection).
ViewshedPyramid trimmedPyramid(const ViewshedPyramid& pyramid, int k);

// Markdown tables on stdout for one field: the build (once, at the finest of `levels`), the
// memory of each choice of finest level, and for a valley, a ground-level and a high observer
// the culled shares and the exact and culled viewsheds' times (the fastest of `reps`,
// interleaved).
void viewshedCullingReport(const ComputeContext& context, const std::string& path, const std::vector<int>& levels,
                           int reps);

}  // namespace hfvis::bench
