// hfvis_testing/horizon_lists_reference.hpp: the brute-force reference of the horizon lists
// (hfvis/horizon_lists.hpp): one receiver's ray sampled as the naive method samples it, and on
// it every sample's visibility and the visibility horizons by their definitions (Timonen 2013,
// Eq. 1 and 2), each decided by the exact chord_side predicate, in O(n^2). Test support
// library hfvis_testing; not installed.
#pragma once

#include <vector>

#include "hfvis/height_field.hpp"
#include "core/sweep_geometry.hpp"

namespace hfvis {

// The receiver (c, r)'s ray in direction d: the heights of samples 1, 2, ... (bilinear in `h`,
// the prepared heights), NaN where absent.
std::vector<float> referenceRay(const HeightField& field, const std::vector<float>& h,
                                const detail::SweepDirection& d, int c, int r);

struct HorizonListReference {
  std::vector<bool> visible;  // by sample index i (0 unused)
  std::vector<int> horizons;  // sample indices, nearest first
};

// Brute force on the ray (sample i at ray[i - 1], receiver height hr at distance 0).
HorizonListReference referenceHorizonList(const std::vector<float>& ray, float hr);

}  // namespace hfvis
