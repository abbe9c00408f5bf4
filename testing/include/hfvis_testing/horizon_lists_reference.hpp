// hfvis_testing/horizon_lists_reference.hpp: the brute-force reference of the horizon lists
// (hfvis/horizon_lists.hpp): one receiver's ray sampled as the naive method samples it, and on
// it every sample's visibility and the visibility horizons by their definitions (Timonen 2013,
// Eq. 1 and 2), with the peaks between samples as occluders, each decided by the exact
// chord_side predicate, in O(n^2). Test support library hfvis_testing; not installed.
#pragma once

#include <cstdint>
#include <vector>

#include "core/sweep_geometry.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis {

// The receiver (c, r)'s ray in direction d: the heights of samples 1, 2, ... (bilinear in `h`,
// the prepared heights), NaN where absent.
std::vector<float> referenceRay(const HeightField& field, const std::vector<float>& h,
                                const detail::SweepDirection& d, int c, int r);

struct HorizonListReference {
  std::vector<bool> visible;  // by sample index i (0 unused)
  std::vector<bool> exactly;  // visible without the rounding forgiven
  std::vector<int> horizons;  // sample indices, nearest first
  int peaks_admitted = 0;     // the peaks among the occluders
};

// A ray's positions and the peaks between its samples (src/ops/horizon_lists_ray.hpp). Positions:
// sample i at i << shift, or with per-row spacing (`positions` not empty, shift 0) at
// positions[i - 1] whole units of ground length; the receiver at 0. Peaks (`heights` empty: none):
// per interval i, between sample i + 1 and sample i (interval 0 ends at the receiver), a height
// (NaN: none) and its offset from sample i + 1 toward sample i in the interval's positions.
struct RayPeaks {
  int shift = 0;
  std::vector<std::int32_t> positions;
  std::vector<float> heights;
  std::vector<std::int32_t> offsets;
};

// Brute force on the ray (sample i at ray[i - 1], receiver height hr at distance 0), every node
// at its position: a sample is visible when it is present and no present sample and no peak
// nearer than it (one that tree_peak_inserted admits: strictly above the chord of its interval's
// samples, at its offset of the interval's positions) lies strictly above the sight line, or
// where the steepest of them hides it only within the heights' rounding and so do the hidden
// samples between it and the next visible node farther out (kernels/shared/chord_side.cl).
// Horizons by Eq. 1 and 2 over the samples and those peaks alike; a peak that is a horizon is
// listed by the sample right after it (nearer) where that one is visible. `height_base`: the
// height the ray's 0 stands for (PreparedHeights::base), for the rounding forgiven.
HorizonListReference referenceHorizonList(const std::vector<float>& ray, float hr, const RayPeaks& peaks = {},
                                          float height_base = 0.0f);

}  // namespace hfvis
