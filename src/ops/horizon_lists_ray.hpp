// horizon_lists_ray.hpp: one receiver's ray as the horizon lists sweep it (its samples, as the
// naive method takes them, and the occluder-only peaks between them, kernels/shared/tree_peaks.cl),
// for src/ops/horizon_lists.cpp and the tests, which check the lists against it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/sweep_geometry.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis::detail {

// The ray from pixel (c, r) along d: sample i (1 = nearest) at index i - 1, at `points[i - 1]`
// (pixel axes), NaN where absent, up to the last sample inside the field; `heights` lowered by
// the Earth's drop at its distance (drop times its distance squared, in float), `surface` the
// bilinear heights before it. With per-row spacing (units: the ray's half-row table of step
// units, naiveRowTables) sample i lies at `positions[i - 1]` whole units of `unit` ground length,
// its step toward the receiver `rings[i - 1]` units long, and the drop is c unit^2 position^2.
// Peaks (shift > 0, or with per-row spacing; empty on a field narrower than a cell): per
// interval i (between sample i + 1 and sample i; interval 0 ends at the receiver), the point of
// the surface between them that stands farthest above their chord (as the lattice lines take it:
// tree_piece_peak over segmentTreePieces), its height lowered by its drop, NaN where none, and
// its offset from sample i + 1 toward sample i in units of 2^-shift step, or with per-row spacing
// in whole units of `unit` (the step's rings[i] of them, as the tree's lines count a peak's
// position on a latitude / longitude grid). Whether it enters the tree is tree_peak_inserted's
// to say, with the interval's positions as its scale.
struct HorizonRay {
  std::vector<Point2> points;
  std::vector<float> heights, surface;
  std::vector<std::int32_t> positions, rings;
  int shift = 0;
  std::vector<float> peaks;
  std::vector<std::int32_t> peak_offsets;
};

HorizonRay horizonRay(const HeightField& field, const std::vector<float>& heights, const SweepDirection& d,
                      int c, int r, double curvature, const std::int32_t* units, double unit, int shift);

// The most samples a ray of the run has (width + height per unit step), and the position shift
// of its rays: treePositionShift of that, 0 with per-row spacing (positions in whole units) or on
// a field narrower than a cell (no peaks).
std::size_t longestHorizonRay(const HeightField& field, const SweepOptions& options);
int horizonRayShift(const HeightField& field, const SweepOptions& options);

}  // namespace hfvis::detail
