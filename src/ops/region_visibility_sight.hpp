// region_visibility_sight.hpp: the region visibility's line-of-sight test and sample placement
// for C++ (the host and the scalar reference): kernels/shared/region_visibility_sight.cl itself,
// the source the kernel compiles, included here so the two cannot drift; and the sample tables
// the kernel takes.
#pragma once

#include <cmath>
#include <vector>

#include "core/opencl_builtins.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/region_visibility.hpp"

namespace hfvis::detail {

#include "../../kernels/shared/region_visibility_sight.cl"

// A region's table for region_sample(): the rectangle (lo_x, lo_y, hi_x, hi_y), then per sample
// its stratum's corner, size and height (explicit points: the point, size 0). Validates
// (validateSampling).
std::vector<float> regionSampleTable(const HeightField& field, const RegionSampling& sampling,
                                     const std::vector<float>* heights = nullptr);

// validate(field, sampling) (hfvis/region_visibility.hpp), explicit points checked against
// `heights` (the field's prepared as HeightOrigin::Zero; nullptr: prepared here).
void validateSampling(const HeightField& field, const RegionSampling& sampling,
                      const std::vector<float>* heights);

// The culling pyramid of kernels/shared/region_visibility_sight.cl (region_cull_*) over the
// z-scaled heights, and the part of the march's rounding that a block's height must clear which
// depends on the field alone (region_sight_visible_culled adds the segment's own).
struct CullPyramid {
  std::vector<float> top;
  int levels = 0;
  float margin = 0.0f;
  float gradient = 0.0f;  // the surface's steepest slope per pixel, at most (region_cull_hides)
  bool finite = true;     // every height finite (region_cull_hides need not look)
};

// `checked`: the path for fields with non-finite heights even where every height is finite (the
// tests compare the two paths; they must give the same pyramid). `bands`: the bands of rows the
// path for finite fields runs in (core/host_bands.hpp); 0, bandsFor's (tests give others: the
// pyramid is the same for any).
CullPyramid cullPyramid(const std::vector<float>& h, int width, int height, bool checked = false,
                        int bands = 0);

// Fills a pair result's clear_pairs, pairs and per-sample fractions from its bits (the samples'
// counts and words set).
void countPairFractions(RegionPairVisibilityResult& out);

// The samples a table holds.
inline int regionTableSamples(const std::vector<float>& table) {
  return static_cast<int>((table.size() - 4) / 5);
}

}  // namespace hfvis::detail
