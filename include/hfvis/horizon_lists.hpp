// hfvis/horizon_lists.hpp: the visibility horizons of chosen receivers (Timonen 2013): for
// each receiver and direction, the horizon points that bound the visible segments of the
// surface along the ray, their distances and elevation angles, and the segments themselves.
// For inspection and for other tools (the CLI writes them as JSON or CSV).
//
// Which samples: the receiver's own ray, exactly the samples of the naive method: from the
// pixel centre p, q_i = p + i * step * d_k for i = 1, 2, ... while inside the field
// (bilinear heights, nodata samples absent), step = 1 / samples_per_unit pixel lengths along
// d_k (directions as in hfvis/sweep_options.hpp), at phi_k exactly. Between two consecutive
// samples (and between sample 1 and the receiver) the bilinear surface can rise above both (a
// one-pixel wall, two roofs touching at a corner seen along a diagonal): there the interval's
// peak, its point farthest above the chord of the two samples (at a grid crossing or inside a
// cell, where the surface along the ray is a quadratic), stands as an occluder, as in the hull
// tree's lattice lines (docs/ALGORITHMS.md): it hides what lies behind it but is no sample. So
// the lists no longer equal the naive method's visible set: a sample is listed visible when no
// sample and no peak nearer than it lies strictly above its sight line from the receiver, each
// decided exactly (peak positions in fixed point, 2^-shift of a step; on latitude / longitude
// grids, per-row spacing, whole units of ground length, the step's own number of them, as the
// hull tree's lines take them there). Where the surface is linear between the samples (rays
// along the axes, a whole number of samples per pixel) that is the naive method's set. The
// hull-tree sweep's counts come from each receiver's own lattice line, a step close to phi_k
// (hfvis/intervisibility.hpp).
//
// Visibility and tie rule as in hfvis/intervisibility.hpp (grazing samples are visible).
// A visibility horizon is the farthest sample of maximal slope from the receiver among the
// samples (and peaks) from one segment start (Eq. 1 of the paper) to the receiver; its visible
// segment runs from it toward the receiver up to the first hidden sample or the next horizon. A
// horizon that is a peak is listed by the sample right after it (nearer), the farthest of its
// segment, and not at all where that sample is hidden. A segment also takes the hidden samples
// farther out that its horizon hides only within the heights' rounding (the tie rule forgives
// it); it is then listed by the farthest of them, which may stand a hair lower than the next
// nearer horizon. The segments together hold every visible
// sample, each once; on a flat plane there is one horizon, the farthest sample, whose segment is
// the whole ray.
//
// Computed on the host by the scalar hull-tree sweep (the mirror of the device kernel, the
// same exact predicate, the same peaks: kernels/shared/tree_peaks.cl) on the receiver's ray: a
// few receivers cost microseconds each.
#pragma once

#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis {

// A receiver, by pixel: column (x) and row (y), zero-based.
struct ReceiverPixel {
  int col = 0;
  int row = 0;
};

// One visibility horizon and the visible segment it bounds. Samples are numbered along the
// ray, 1 = nearest; sample i lies at ground distance i * sample_spacing (with per-row spacing,
// a latitude / longitude grid, the sum of its steps' ground lengths, each at its middle row
// in whole units of groundUnit, as the visibility kernels take them).
struct VisibilityHorizon {
  int sample = 0;              // the horizon point: the farthest visible sample of its segment
  double distance = 0.0;       // its ground distance from the receiver (ground units)
  double elevation = 0.0;      // its elevation angle atan2(dz, distance), radians
  int segment_begin = 0;       // the segment: samples [segment_begin, segment_end), all present
  int segment_end = 0;         //   ones visible; segment_end = sample + 1
  double near_distance = 0.0;  // ground distance of sample segment_begin
  int visible_samples = 0;     // present samples in the segment (fewer than its length at holes)
};

struct DirectionHorizons {
  int direction = 0;                        // k
  double azimuth = 0.0;                     // phi_k, radians
  double sample_spacing = 0.0;              // ground distance between consecutive samples (the first
                                            // step's with per-row spacing)
  int ray_samples = 0;                      // samples on the ray inside the field, present or not
  int visible_samples = 0;                  // visible samples, the sum over the segments
  std::vector<VisibilityHorizon> horizons;  // nearest first; elevations never decrease, but within
                                            // the heights' rounding (a forgiven sample's)
};

struct ReceiverHorizons {
  ReceiverPixel pixel;
  float height = 0.0f;                        // the input height at the pixel (before z-scale); NaN at nodata
  bool nodata = false;                        // nodata receivers see nothing: every list is empty
  std::vector<DirectionHorizons> directions;  // K, in direction order
};

// Throws InvalidArgument naming the first receiver outside the field.
void validateReceivers(const HeightField& field, const std::vector<ReceiverPixel>& receivers);

// The lists for every receiver, in the order given (options.curvature lowers each sample by
// its drop, as the naive march does, and each peak by its own: the peak is chosen on the surface
// before the drop, as the lattice lines choose it). options.memory_budget_bytes and
// progress are not used (one ray per receiver and direction).
// Throws InvalidArgument for a bad field, bad options or a receiver outside the field.
std::vector<ReceiverHorizons> computeHorizonLists(const HeightField& field, const SweepOptions& options,
                                                  const std::vector<ReceiverPixel>& receivers);

}  // namespace hfvis
