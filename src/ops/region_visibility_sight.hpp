// region_visibility_sight.hpp: the region visibility's line-of-sight test and sample placement
// for C++ (the host and the scalar reference): kernels/shared/region_visibility_sight.cl itself,
// the source the kernel compiles, included here so the two cannot drift; and the sample tables
// the kernel takes.
#pragma once

#include <cmath>
#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/region_visibility.hpp"
#include "core/opencl_builtins.hpp"

namespace hfvis::detail {

#include "../../kernels/shared/region_visibility_sight.cl"

// A region's table for region_sample(): the rectangle (lo_x, lo_y, hi_x, hi_y), then per sample
// its stratum's corner, size and height (explicit points: the point, size 0). Validates.
std::vector<float> regionSampleTable(const HeightField& field, const RegionSampling& sampling);

// Fills a pair result's clear_pairs, pairs and per-sample fractions from its bits (the samples'
// counts and words set).
void countPairFractions(RegionPairVisibilityResult& out);

// The samples a table holds.
inline int regionTableSamples(const std::vector<float>& table) {
  return static_cast<int>((table.size() - 4) / 5);
}

}  // namespace hfvis::detail
