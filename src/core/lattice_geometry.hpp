// lattice_geometry.hpp: the receiver-exact sweep geometry of the horizon operation. A
// direction is a primitive integer step (a, b) in pixel axes; every pixel centre lies on
// exactly one line of that direction, so every receiver is a sample of the line through
// its own centre and its hull-stack horizon is the horizon of its own ray. Between two
// consecutive pixel centres of a line the samples sit where the line crosses the grid's
// columns and rows (there the bilinear surface is linear, so these heights are exact) and,
// with denser sampling, between consecutive crossings (inside a cell the surface is a
// quadratic along the ray, which can peak between them). The pattern is the same for every period of every
// line, so it is one small table per direction. Shared by the kernels' host code and the scalar references,
// so both sample the very same points.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis::detail {

// One sweep direction of a run.
struct LatticeDirection {
  int a = 1, b = 0;               // primitive step between consecutive receivers of a line (columns, rows)
  double azimuth = 0.0;           // ground azimuth of (a, b), radians
  double weight = 0.0;            // share of the circle of azimuth it stands for (sums to 1 over a run)
  double ground_per_pixel = 1.0;  // ground length of one pixel length along (a, b)
  double period = 1.0;            // |(a, b)| in pixels: distance between consecutive receivers of a line
};

// The directions of a run. With `exact_azimuths` (per-direction planes requested),
// direction k is the cheapest primitive step whose ground azimuth is within `tolerance`
// radians of phi_k = 2 pi k / K + offset (the closest one when none is), each with weight
// 1/K. Otherwise (sky-view factor, occlusion and the hull tree's counts, which integrate
// over azimuth) the cheapest strictly within half the spacing 2 pi / K, with quadrature
// weights from the azimuths actually used (half the gap to each neighbour). "Cheapest" is the fewest
// crossings per period, |a| + |b| - 1 (1 on the axes), and among those the closest to phi_k.
// Steps are bounded by kMaxLatticeStep, but a single exact direction (K = 1: the sun's sweeps)
// that no such step comes within `tolerance` of takes the cheapest longer one that does, of up to
// kMaxExactStep pixels (about 0.014 degree from an axis: a step's cost, its crossings per
// receiver, is paid once). Quadrature directions that fall back to the same step (very large K)
// are merged: one carries their weight, the others have weight 0 and are not swept; with
// `parity_apart` (the error estimate's halves, HorizonOutputs::error_estimate) only those of
// the same parity of k, so that each half keeps the azimuths it stands for.
constexpr int kMaxLatticeStep = 64;
constexpr int kMaxExactStep = 4096;
std::vector<LatticeDirection> latticeDirections(const HeightField& field, const SweepOptions& options,
                                                bool exact_azimuths, double tolerance, bool parity_apart = false);

// The direction of primitive step (a, b) over a field (azimuth and ground length from its
// cell sizes; weight left 0).
LatticeDirection latticeStep(const HeightField& field, int a, int b);

// One sample of a period, as the kernel reads it (nine 4-byte members, uploaded as is; must
// match LatticeSample in kernels/horizon.cl). The sample lies at `tau` pixels from the
// period's receiver toward +(a, b), in the cell whose lower corner is (ox, oy) from the
// receiver, at fractions (fx, fy) with bilinear weights w00..w11; ex (ey) is 1 when fx
// (fy) > 0, i.e. when the cell's far column (row) is needed.
struct LatticeSample {
  float tau;
  std::int32_t ox, oy, ex, ey;
  float w00, w10, w01, w11;
};
static_assert(sizeof(LatticeSample) == 36, "LatticeSample must match the kernel struct");

// The samples of one period of direction d, farthest first; the last one is the receiver
// itself (tau = 0). Each interval between consecutive crossings (at most a cell diagonal
// long) is cut into max(1, round(S * length)) equal parts (S = samples per unit): S = 1
// takes the crossings alone, larger S adds points between them about 1/S pixel apart,
// where the surface can peak inside a cell. Lines along a grid row or column have only
// their pixel centres: the surface is linear between them.
std::vector<LatticeSample> latticeSamples(const LatticeDirection& d, double samples_per_unit);

// The piece of a line between two consecutive samples of the horizon sweep (CellSegment q
// runs from the sample before sample q, farther along +(a, b), to sample q; segment 0 from the
// next receiver along +(a, b), at tau = period). Such a piece lies inside one cell, where the
// bilinear surface is a quadratic in the distance along the line: off the grid lines (`curved`)
// it can peak strictly inside the piece, above both samples (two high corners off a diagonal:
// roofs that touch at a corner, a one-pixel wall, a street canyon seen diagonally). The kernel
// adds that maximum as a sample of its own where it lies strictly inside (horizon_lattice's
// segment_peak). The cell's lower corner is (ox, oy) from the receiver; along the piece its
// cell fractions run from (fx, fy) at the far end (tau_far) by (dx, dy) to the near end
// (tau_near, the sample's own tau). A crossing (or a receiver) reads the two corners it lies
// between, so the kernel takes what it can of the cell's four corners from its ends: from00 ..
// from11 say where corner (0, 0) .. (1, 1) of the cell is, 0 and 1 the far end's first and
// second corner, 2 and 3 the near end's, 4 at neither (read it). Thirteen 4-byte members,
// uploaded as is; must match CellSegment in kernels/horizon.cl.
struct CellSegment {
  float tau_far, tau_near;
  std::int32_t ox, oy;
  float fx, fy, dx, dy;
  std::int32_t curved;
  std::int32_t from00, from10, from01, from11;
};
static_assert(sizeof(CellSegment) == 52, "CellSegment must match the kernel struct");

// The segments that end at each of latticeSamples(d, samples_per_unit) (the same count and
// order).
std::vector<CellSegment> cellSegments(const LatticeDirection& d, double samples_per_unit);

// Hull-stack entries one period of the horizon sweep can push: its samples and the peaks
// inside its curved segments.
std::size_t stackEntriesPerPeriod(const std::vector<CellSegment>& segments);

// The hull tree's samples (the intervisibility sweep): `per_period` equally spaced samples
// of one period, farthest first, the receiver last, so steps along a line are uniform
// (period / per_period pixels) and the tree's geometry stays in exact integer steps.
// samplesPerPeriod: ceil(period * S), at least 1: steps of at most 1 / S pixel.
int samplesPerPeriod(const LatticeDirection& d, double samples_per_unit);
std::vector<LatticeSample> uniformLatticeSamples(const LatticeDirection& d, int per_period);

// A piece of the line between two consecutive hull-tree samples, inside one cell
// (kernels/shared/tree_peaks.cl says what the tree makes of them): the cell's lower corner
// (ox, oy) from the period's receiver, the cell fractions (fx, fy) at the piece's far end and
// their change (dx, dy) to its near end, where its ends lie in the interval (t_far, t_near: 0
// at the far sample, 1 at the near one) and 1 / (t_near - t_far), and whether its far end is a
// grid-line crossing (the interval's far sample is not). Ten 4-byte members, uploaded as is;
// the kernel reads them field by field.
struct TreePiece {
  std::int32_t ox, oy;
  float fx, fy, dx, dy, t_far, t_near, inv_span;
  std::int32_t far_crossing;
};
static_assert(sizeof(TreePiece) == 40, "TreePiece must match the kernel's reads");

// The pieces of the intervals of one period of direction d sampled per_period times
// (uniformLatticeSamples): interval q ends at sample q (its far end is sample q - 1, or for q = 0
// the receiver of the period before); its pieces are pieces[first[q] .. first[q + 1]), farthest
// first. None on lines along a grid row or column (the surface is linear between pixel
// centres there, so no point between samples rises above both).
struct TreeIntervals {
  std::vector<TreePiece> pieces;
  std::vector<std::int32_t> first;  // per_period + 1 entries
};
TreeIntervals treeIntervals(const LatticeDirection& d, int per_period);

// The pieces of one interval of an arbitrary line (the horizon lists' rays, whose samples are
// not on a lattice): the segment from (x_far, y_far) to (x_near, y_near), in pixel axes inside
// a width x height field (at least 2 x 2), cut where it crosses a column or a row strictly
// between its ends (a vertex once), farthest first. Cell origins are absolute, kept within the
// field's cells (a piece along the last column or row lies on its cell's far edge).
std::vector<TreePiece> segmentTreePieces(double x_far, double y_far, double x_near, double y_near, int width,
                                         int height);

// One line of a direction: its farthest receiver (along +(a, b)) and how many receivers it
// has; receiver i sits at (col - i a, row - i b). `stack` is the first entry of its hull
// stack in the scratch buffer (entries at stack + depth * stride).
struct LatticeLine {
  std::int32_t col, row, receivers, stack;
};
static_assert(sizeof(LatticeLine) == 16, "LatticeLine must match the kernel's int4");

// Every line of direction d over a width x height field that holds a receiver, stack
// offsets left at 0.
std::vector<LatticeLine> latticeLines(const LatticeDirection& d, int width, int height);

// Lines [first, first + count) of a direction, as one launch runs them, with their hull
// stacks laid out in one scratch buffer: line-major (each line's stack contiguous, at the
// sum of the capacities before it; stride 1) for CPUs, step-major (depth k of line j at
// k * count + j, stride count) for GPUs. Capacity: every sample of the line's periods.
struct LineChunk {
  std::size_t first = 0, count = 0;
  std::size_t stack_entries = 0;  // scratch entries the chunk needs
  std::uint32_t stride = 1;
};
// Splits `lines` into chunks whose scratch fits `max_entries` (at least one line each),
// setting each line's stack offset within its chunk. With `align`, chunks start at multiples of
// `align` lines only (lanes of a work-item that must come from one group of lines; a chunk then
// holds at least `align` lines, and may need their scratch beyond `max_entries`).
std::vector<LineChunk> chunkLines(std::vector<LatticeLine>& lines, std::size_t samples_per_period,
                                  std::size_t max_entries, bool line_major, std::size_t align = 1);
// The same with each line's capacity given (a strip's part of a line: its samples there and
// the stack it arrives with).
std::vector<LineChunk> chunkLines(std::vector<LatticeLine>& lines, const std::vector<std::size_t>& capacities,
                                  std::size_t max_entries, bool line_major, std::size_t align = 1);

// The index of receiver (col, row) of this field along its line of step (a, b) through the larger
// field it was cut from (HeightField::origin; without one, this field): how many receivers of
// that line lie beyond it along +(a, b). The horizon sweep places sample positions from it
// (receiver_index in kernels/horizon.cl: the same integer arithmetic), so that a field cut out
// of a larger one meets every sample where the larger field does.
int receiverIndex(const HeightField& field, int a, int b, int col, int row);

// The receivers [first, end) of a line of a direction with row step b that lie in rows
// [first_row, end_row) (a strip); first == end when none do.
std::pair<int, int> receiversInRows(const LatticeLine& line, int b, int first_row, int end_row);

// Scratch entries one line needs (its capacity): a direction can always be run one line at
// a time.
std::size_t lineCapacity(const LatticeLine& line, std::size_t samples_per_period);

// The ground length of one position unit on a field with per-row spacing: the field's
// extent (W + H plus twice the longest lattice period, 64 sqrt 2, in pixels, times the largest
// cell size) over 2^23, so a line's or ray's position, each of its steps rounded to whole
// units, stays below 2^24 (checked: checkTreeLimits). A step's ground length is then off by
// at most half a unit: a relative 2^-24 (W + H + 181) / (the step's pixels). Every run on the
// field takes the same unit (the tree, the naive march, the horizon lists, any K), so where they
// sample the same points they see the same positions; a field cut from a larger one
// (HeightField::origin) takes the larger field's.
double groundUnit(const HeightField& field);

// The horizon sweep's unit of position on a field with per-row spacing (HFVIS_ROW_SPACING,
// latticeRowTables): W + H times the largest cell size over 2^23 (the larger field's with an
// origin). A lattice line's periods span at most W + H - 2 pixels of columns and rows, so its
// positions, each period's ground length rounded to whole units (off by half a unit at most),
// stay below 2^24: exact sums in single precision. A period's ground length is then off by a
// relative 2^-24 (W + H) (largest cell) / (its own) at most, about what single precision's
// rounding at the far end of a line gives; finer than groundUnit, whose room for the hull tree's
// predicate and rays the sweep does not need.
double sweepUnit(const HeightField& field);

// A maximum distance along direction d as horizon_lattice takes it (HFVIS_MAX_DISTANCE):
// `window` position units along the line (pixels: max_distance over the ground length per pixel;
// with per-row spacing, units of sweepUnit: max_distance over it) and its reciprocal, whose
// product with a position is the position's block. Both the kernel and the reference get these
// very floats. Both 0 without a maximum distance. Throws InvalidArgument when the window is so
// short that a position's block would overflow an int.
struct LatticeWindow {
  float window = 0.0f, inv_window = 0.0f;
};
LatticeWindow latticeWindow(const HeightField& field, const LatticeDirection& d, double max_distance);


// Signed difference of two angles (radians), in (-pi, pi].
double angleDifference(double x, double y);

// Nested quadrature sets (HorizonOptions::max_error's sky-view factor and occlusion): a run adds
// directions to those before instead of computing a new set. Copy c = 0, 1, 2, ... holds `base`
// directions, direction k aimed at 2 pi (k + v(c)) / base + offset, v the van der Corput sequence
// 0, 1/2, 1/4, 3/4, 1/8, ... (vanDerCorput): the first m copies together aim at the m base
// azimuths of the uniform set of m base directions when m is a power of 2, and fill its gaps in
// halves otherwise. Each direction takes the cheapest step strictly within half the spacing of
// the set its copy completes (nestedLevelCopies(c) copies, the least power of 2 above c; the
// closest step when none is inside, as latticeDirections does), so that a copy added late is as
// close to its azimuths as a uniform set of that K, and one added early as cheap as a coarse one.
// Each copy is weighted by its own half gaps (setQuadratureWeights with parity_apart: its weights
// sum to 1): the set's quadrature is the mean of its copies'. Copy 0 alone is the uniform set of
// `base` directions (latticeDirections' steps and weights with the error estimate's halves).
// nestedCopySteps gives copies [first, end), in order.
double vanDerCorput(int c);
int nestedLevelCopies(int c);
std::vector<LatticeDirection> nestedCopySteps(const HeightField& field, double azimuth_offset, int base, int first,
                                              int end);

// Quadrature weights of directions at these azimuths (in increasing order around the circle):
// half the gap to each neighbour, over 2 pi (1 for one direction, 1/2 each for two).
std::vector<double> halfGapWeights(const std::vector<double>& azimuths);

// Sets the directions' weights from their azimuths (halfGapWeights); steps that coincide
// are merged: the first takes their weight, the others get 0 and are not swept (with
// `parity_apart`, only steps whose indices have the same parity).
void setQuadratureWeights(std::vector<LatticeDirection>& directions, bool parity_apart = false);

// The cell sizes at row y (fractional), linear between the rows' per-row sizes, clamped.
void cellSizeAtRow(const HeightField& field, double y, double* cell_x, double* cell_y);

}  // namespace hfvis::detail
