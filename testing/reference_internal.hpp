// reference_internal.hpp: line-level pieces of the scalar references, for tests that
// check a sweep line by line against brute force.
#pragma once

#include <vector>

#include "hfvis/height_field.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"
#include "core/lattice_geometry.hpp"

namespace hfvis::detail {

// One sample of a lattice line as the sweep meets it (farthest first): its height (NaN =
// absent; only receivers are listed then), its position along the line (pixels from the
// line's far end; with HeightField::origin, from the far end of the line through the larger
// field), the receiver pixel it is (-1 for samples between receivers), and what
// the hull stack gave it: the occluder's stack depth (-1 = none), its rise above the sample
// and its distance along the line (pixels).
struct LatticeLineSample {
  float height = 0.0f;
  float position = 0.0f;
  long receiver = -1;
  long occluder = -1;
  float occluder_rise = 0.0f, occluder_run = 0.0f;
  bool peak = false;  // the surface's maximum inside the segment before the next sample
};

// The samples of one line of direction d (prepared heights h), with Algorithm 1 run over
// them exactly as horizon_lattice runs it (latticeSamples and the peaks inside cellSegments at
// samples_per_unit); with `drop` (curvature per pixel squared along the
// line) the stack holds the heights lowered by drop * position^2, and occluder_rise is that
// stack's (the receiver adds -2 drop position run). With a window (a maximum distance), as
// horizon_lattice with HFVIS_MAX_DISTANCE: the receivers' occluders are the steepest samples
// within the window (occluder 0 where it lies in the block before the receiver's); the other
// samples' occluders are those of their own block only. With per-row spacing (`rows`, the
// direction's latticeRowTables entry) positions are whole units of sweepUnit summed period by
// period from the line's position along the larger field's line (lineStartPosition), as
// HFVIS_ROW_SPACING makes them.
std::vector<LatticeLineSample> latticeLineSamples(const HeightField& field, const std::vector<float>& h,
                                                  const LatticeDirection& d, double samples_per_unit,
                                                  const LatticeLine& line, float drop = 0.0f,
                                                  const LatticeWindow& window = {},
                                                  const RowTable* rows = nullptr);

// lattice_height in the kernels: the bilinear height of sample s whose cell corner is at
// entry `at` (right = 1 or 0, down = width or 0), over the valid corners.
float latticeHeight(const std::vector<float>& h, std::size_t at, std::size_t right, std::size_t down,
                    const LatticeSample& s);

// The canonical lines of tree direction d over prepared heights (or any plane sampled like
// them), as intervisibility_lattice samples them: geometry, receiver_every, samples and peaks
// set (with `curvature`, lowered by d.drop times their position squared), nothing swept yet.
IntervisibilityLines latticeTreeLines(const HeightField& field, const std::vector<float>& prepared_heights,
                                      const TreeDirection& d, bool curvature = false);
// Sets the peaks of lines (canonical lines of d, samples set) from the heights, as
// intervisibility_lattice computes them (kernels/shared/tree_peaks.cl).
void addTreePeaks(const HeightField& field, const std::vector<float>& heights, const TreeDirection& d,
                  bool curvature, IntervisibilityLines& lines);

// The pixel of the receiver at step i (a receiver step) of line j of d.
std::size_t receiverPixel(const TreeDirection& d, int width, int j, int i);

}  // namespace hfvis::detail
