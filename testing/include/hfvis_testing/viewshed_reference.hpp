// hfvis_testing/viewshed_reference.hpp: the viewshed by brute force in double precision: every sight
// line decided exactly, cell by cell, on the bilinear surface (hfvis/viewshed.hpp's
// definition). The oracle of the viewshed tests and the reference of its benchmark (test
// support library hfvis_testing; not installed).
#pragma once

#include <vector>

#include "hfvis/viewshed.hpp"

namespace hfvis {

// One sight line: visible (the surface rising above it nowhere by more than the heights' rounding
// it forgives, forgiven_rise in kernels/viewshed.cl), and how far the surface rises above the sight line at
// most over [0, 1] (height units; <= 0 where visible), and the same strictly between eye and target
// (-infinity where the line crosses no grid line): how near to grazing it is, not counting the
// target's own point, where a target on the surface always touches its sight line.
struct SightLine {
  bool visible = false;
  double rise = 0.0;
  double interior_rise = 0.0;
  double excess = 0.0;  // the largest f(t) / t over (0, 1], f the surface less the sight line
};

// The sight line from `observer` to the target on grid point (col, row), in range or not.
SightLine referenceSightLine(const HeightField& field, const Observer& observer, const ViewshedOptions& options,
                             int col, int row);

// Every target as computeViewshed decides them (visible, angle and needed height), in double;
// `rise`, when given, gets each in-range target's SightLine::rise (NaN elsewhere).
ViewshedResult referenceViewshed(const HeightField& field, const Observer& observer, const ViewshedOptions& options,
                                 std::vector<double>* rise = nullptr);

// The culling pyramid's query (viewshed_cull in kernels/viewshed.cl) in double, without the
// kernel's widening for its float rounding: 1 where a point's node is culled, 0 elsewhere, NaN
// at nodata.
std::vector<float> referenceCulledMask(const HeightField& field, const ViewshedPyramid& pyramid,
                                       const Observer& observer, const ViewshedOptions& options);

}  // namespace hfvis
