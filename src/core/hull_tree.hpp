// hull_tree.hpp: what every operation on the convex hull tree sweep (Timonen 2013) shares, on
// the device and in the scalar references (intervisibility, the bounce, the horizon lists, the
// tests): direction geometry, and the line-level view of one direction's sweep (per-sample
// counts, horizons, iterations and the bounce gather), to compare a sweep line by line.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/intervisibility.hpp"
#include "core/horizon_common.hpp"
#include "core/lattice_geometry.hpp"
#include "core/sweep_geometry.hpp"

namespace hfvis::detail {

// One direction of the hull tree sweep: a lattice direction (every pixel centre on one of
// its lines, see lattice_geometry.hpp) sampled uniformly, per_period samples per period, and
// what the kernels scale its results by. The same for the device path and the references.
struct TreeDirection {
  LatticeDirection lattice;
  int index = 0;                       // k of the (first) phi_k it sweeps for
  int per_period = 1;                  // samples per period (the receiver included)
  std::vector<LatticeSample> samples;  // uniformLatticeSamples
  std::vector<LatticeLine> lines;      // its lines over the field
  float step_length = 1.0f;            // pixels between consecutive samples: period / per_period
  float step_ground = 1.0f;            // their ground distance
  // count_sum += count_factor * visible samples: K * weight * step_length * S, so that a
  // direction's count is its visible length in units of 1 / S pixel (the naive march's
  // visible samples) and the sum over directions is K times its quadrature mean.
  float count_factor = 1.0f;
  // area_sum += area_factor * (sum of the visible samples' steps from the receiver):
  // 2 pi weight * step_ground^2, the ring sectors the samples stand for.
  float area_factor = 0.0f;
  // The Earth's drop per step squared, c step_ground^2 (SweepOptions::curvature).
  float drop = 0.0f;
  // Steps within the maximum distance: floor(max_distance / step_ground), or kAllSteps.
  int max_steps = kAllSteps;
  float half_sector = 0.0f, wedge = 0.0f;  // the bounce's pi weight and 2 sin(pi weight)
  float cos_azimuth = 1.0f, sin_azimuth = 0.0f;
  // Per-row spacing (a latitude / longitude grid; row_units empty otherwise): positions along
  // a line are whole units of groundUnit(field) ground length, so that the exact
  // predicate keeps integer differences. The period ending at a receiver of row r (toward
  // +(a, b), at its middle row, as the horizon sweep takes it) has per_period steps of
  // row_units[r] units each; that receiver adds row_factors[2 r] * visible samples to its
  // count and row_factors[2 r + 1] * its distance sum (units squared) to its area: the
  // count and area factors with the step's weight at that row. drop is then per unit
  // squared and max_steps counts units.
  std::vector<std::int32_t> row_units;
  std::vector<float> row_factors;
  bool rowSpacing() const { return !row_units.empty(); }
  std::size_t longestLine() const;  // entries (steps) of its longest line
  // The occluder-only peaks between consecutive samples (kernels/shared/tree_peaks.cl): the
  // pieces of each interval of a period, and the fixed point of positions along a line: a
  // sample at step s lies at s << position_shift, a peak between steps s - 1 and s at
  // (s - 1) << position_shift plus its offset. With per-row spacing (position_shift 0) the
  // positions are whole units of ground length, a peak's the step before's plus its offset in
  // the step's units (groundUnit makes a step thousands of them). A line has two tree slots
  // per step: 2 s for the peak before step s, 2 s + 1 for the sample.
  TreeIntervals intervals;
  int position_shift = 0;
  std::size_t slotsPerPeriod() const { return samples.size() * 2; }
};

// The position shift of a direction whose longest line has `steps` steps: sub-step positions
// as fine as 2^-8 step where the line is short enough, always at least 1 bit (checkTreeLimits
// keeps lines below 2^23 steps), positions below 2^23.
int treePositionShift(std::size_t steps);

// The tuning a sweep runs: `requested`, without the safe zone on lines of per-row spacing
// (its bound interpolates over uniform steps).
inline HullTreeTuning tuningFor(HullTreeTuning requested, bool row_spacing) {
  if (row_spacing) requested.safe_zone = false;
  return requested;
}

// The naive march's tables on a field with per-row spacing (intervisibility_naive with
// HFVIS_ROW_SPACING), for every ray, ray after ray: the step units by half row (2 H - 1 per
// ray, entry k for a step whose middle is at row k / 2), and per row the count factor K w and
// the area factor 2 pi w unit^2 (2 H per ray), w the ray's weight at that row (rayRowTables).
struct NaiveRowTables {
  std::vector<std::int32_t> units;
  std::vector<float> factors;
};
NaiveRowTables naiveRowTables(const HeightField& field, const std::vector<SweepDirection>& rays, double unit);

// The units of step i of a ray from row `row` (step_y rows a step) in its half-row table
// `units` (height rows): the entry of the step's middle, as intervisibility_naive's
// ray_half_row takes it, the same float operations.
inline std::int32_t rayStepUnits(const std::int32_t* units, int height, int row, int i, float step_y) {
  const float mid = static_cast<float>(i) - 0.5f;
  const int half = static_cast<int>(std::nearbyint(2.0f * (static_cast<float>(row) + mid * step_y)));
  return units[std::clamp(half, 0, 2 * height - 2)];
}

// Whole units (at least 1) of a step of (dx, dy) pixels whose middle is at row y (fractional:
// cell sizes interpolated between rows, cellSizeAtRow).
std::int32_t stepUnits(const HeightField& field, double y, double dx, double dy, double unit);

// The directions of a run: the quadrature lattice steps of sky-view factor and ambient
// occlusion (the cheapest step within half the spacing 2 pi / K of each phi_k; latticeDirections),
// steps merged into an equal one left out, each weighted by the wedge of azimuth of its phi_k,
// 1 / K (K / K' for a step that K' of the phi_k merged into), as the naive march weighs its
// rays: the step lies inside that wedge, so the K steps are a one-point-per-wedge quadrature of
// the azimuthal integral. The cheapest steps: a step closer to phi_k has a longer period, and a
// period of P pixels takes P samples per pixel. Not the half gaps between the steps' azimuths
// (the horizon sweep's weights): the cheap steps next to an axis or a diagonal lie far from
// phi_k (at K = 64, (7, 1) at 8.1 deg for phi_1 = 5.6 deg), so the half gaps give the axes and
// diagonals up to 1.45 / K, and visible lengths peak sharply there (streets, brick joints and
// rows of blocks seen down their length). Against a reference dense in azimuth (256 directions,
// the benchmark's vis_accuracy; tests/test_intervisibility.cpp), the wedge weights are the
// closer quadrature on every content measured, at K = 16 to 128.
// With per-row spacing each row gets its steps' lengths and weights there (row_units,
// row_factors), unless `follow_rows` is false (the bounce: the centre latitude's spacing).
// `parity_apart` (the error estimate's halves, IntervisibilityOutputs::error_estimate): steps
// merge only with steps of the same parity of k, so that each half keeps its own wedges.
std::vector<TreeDirection> treeDirections(const HeightField& field, const SweepOptions& options,
                                          bool follow_rows = true, bool parity_apart = false);
// The error estimate (IntervisibilityOutputs::error_estimate) from the count's sums of the
// even-numbered directions in `result` and those of the odd-numbered ones, the directions' wedges
// summed by half: per pixel the halves' difference (each over its own wedges) over the field's
// mean count. Fills error_estimate and estimated_error, and leaves the two halves' totals of the
// count and (when result.visible_area is not empty) of the area in `result`.
void splitVisibilityHalves(IntervisibilityResult& result, const std::vector<float>& odd_count,
                           const std::vector<float>& odd_area, double even_weight, double odd_weight);

// One of them: `lattice` (its weight set) sampled at S samples per unit, in a run of K directions.
TreeDirection makeTreeDirection(const HeightField& field, const LatticeDirection& lattice, double samples_per_unit,
                                int directions, double curvature = 0.0, double max_distance = 0.0);

// Sets d's per-row members (see TreeDirection) on a field with per-row spacing: each row's
// step length in units of `unit` (stepUnits at the period's middle row, as the naive march's
// table takes them) and its weight there (`rows`: latticeRowTables' for d's run).
void followRows(TreeDirection& d, const HeightField& field, const RowTable& rows, double unit,
                double samples_per_unit, int directions, double curvature, double max_distance);

// Limits of the kernels' exact arithmetic, checked before launching: a line has fewer than
// 2^24 steps (steps are exact floats in the predicate), and |height| * steps stays far
// below FLT_MAX (the predicate's products). Throws InvalidArgument saying what to change.
void checkTreeLimits(const std::vector<TreeDirection>& directions, const std::vector<float>& prepared_heights);
// The same for lines of at most `longest_steps` steps.
void checkStepLimits(std::size_t longest_steps, const std::vector<float>& prepared_heights);

// 2*pi/K: the azimuthal sector one direction of the naive march stands for in the area.
float intervisibilitySector(const IntervisibilityOptions& options);

// One direction's per-sample results in step-major order whatever the device's line
// layout: entry (step i, line j) at i * geometry.n_lines + j. Absent samples: NaN sample,
// NaN count and distance sum, zero statistics and hash. Receivers are the steps i with
// i % receiver_every == receiver_every - 1 (every step on the horizon lists' rays; the
// pixel centres on lattice lines): only they get counts, distance sums, horizons and
// hashes; every present sample is inserted into the tree (iterations).
struct IntervisibilityLines {
  SweepDirection geometry{};
  int receiver_every = 1;
  int max_steps = kAllSteps;  // only samples within this many steps (units) of a receiver count
  // Per-row spacing (empty otherwise): per entry, its position along the line in whole units
  // and the units of the step that reached it (the ring width of its share of the area);
  // distance sums are then sums of (receiver position - position) * units. Without, both
  // are the step.
  std::vector<std::int32_t> positions, step_units;
  // Peaks (empty: none, as a test sweeps lines to compare): per entry, the highest point of the surface
  // between the step before and this one (NaN where none: no curved piece, a cell outside the
  // field or with nodata) and its offset from the step before, in units of 2^-position_shift
  // step (with positions: in the step's units). The sweep inserts it before the sample, as an
  // occluder alone, where it stands above the chord of both samples (tree_peak_inserted).
  // Tree slots (horizon_steps, hashes) are then 2 s + 1 for step s's sample and 2 s for its peak.
  int position_shift = 0;
  std::vector<float> peaks;
  std::vector<std::int32_t> peak_offsets;
  float height_base = 0.0f;                  // the height the samples' 0 stands for (PreparedHeights::base)
  std::vector<std::uint32_t> peak_horizons;  // output: an inserted peak's m (statistics' bound)
  bool horizons_at_every_sample = true;  // else only receivers read theirs (the kernels without statistics)
  std::vector<float> samples;                 // sampled heights
  std::vector<float> counts;                  // visible samples (farther along the line)
  std::vector<float> distance_sums;           // sum of their distances, in steps
  std::vector<std::uint32_t> horizons;        // m_i: distinct visibility horizons
  std::vector<std::uint32_t> iterations;      // t_i: convexity checks made (by the tuning)
  std::vector<std::uint32_t> horizon_hashes;  // FNV-1a over the horizons' steps, farthest first
  std::vector<std::uint32_t> walks_skipped;   // 1 where the safe zone skipped the walk
  // Reference only, when asked: the horizons' steps, farthest first, and where each one's
  // visible run begins (the horizon, or the farthest sample of the hidden ones farther out that
  // it hides only within the heights' rounding: forgiven_stretch()) and ends (run_end(): the
  // first hidden sample, the next horizon or the receiver), so horizon h's visible samples are
  // the present ones of slots [start, end).
  std::vector<std::vector<int>> horizon_steps;
  std::vector<std::vector<int>> horizon_run_starts;
  std::vector<std::vector<int>> horizon_run_ends;

  // Every per-entry result for samples.size() entries: NaN counts and sums, zero statistics.
  void resetResults(bool keep_horizons = false);
};

// The canonical lines of tree direction d (geometry, receiver_every, every sample absent):
// lines in the order of d.lines, each padded with absent samples to the longest.
IntervisibilityLines canonicalTreeLines(const TreeDirection& d);

// The bounce gather on one direction's lines (see hfvis/bounce.hpp for the formula), in the
// canonical step-major order of IntervisibilityLines. Inputs per entry: the exit radiance
// channels, then the receiver's unit normal (x, y, z), kBounceNormalFloats after them.
struct BounceLines {
  int channels = 1;
  float half_sector = 0.0f;       // D / 2, D: the wedge of azimuth the direction stands for
  float wedge = 0.0f;             // 2 sin(D / 2): the wedge integral of cos(phi - phi_k)
  float step_ground = 1.0f;       // ground length of one step
  std::vector<float> attributes;  // (channels + 3) floats per entry
  std::vector<float> irradiance;  // output: channels floats per entry; NaN where absent
};
constexpr int kBounceNormalFloats = 3;

// The bounce gather's inputs as the device and the reference see them (prepareBounce):
// prepared heights (see prepareHeights), the unit normals of the four quads around each pixel
// (ambient occlusion's, in ground units) as three planes x, y, z, and the radiance planes;
// normals and radiance NaN at nodata pixels.
struct BounceInputs {
  std::vector<float> heights;
  float height_base = 0.0f;  // PreparedHeights::base of `heights`
  bool has_nodata = false;
  std::vector<std::vector<float>> normals;   // 3 planes
  std::vector<std::vector<float>> radiance;  // 1..4 planes
  int channels() const { return static_cast<int>(radiance.size()); }
};

// Runs the reference hull-tree sweep over lines whose `geometry` (n_lines, n_steps, and
// the step's ground length) and `samples` are set: fills every other per-entry vector;
// keep_horizons fills horizon_steps and horizon_run_ends; `bounce`, when given, gathers.
void sweepPresampledLines(IntervisibilityLines& lines, const HullTreeTuning& tuning, bool keep_horizons,
                          BounceLines* bounce = nullptr);

// FNV-1a step of the horizon hash (kernel: `hash = (hash ^ step) * 16777619u`).
constexpr std::uint32_t kHorizonHashSeed = 2166136261u;
inline std::uint32_t hashHorizon(std::uint32_t hash, int step) {
  return (hash ^ static_cast<std::uint32_t>(step)) * 16777619u;
}

// The hull-tree sweep kernel for one direction on prepared heights (see prepareHeights: their
// base sets the tie rule's rounding, as in production), with per-entry statistics, as lattice
// lines in the canonical order above (lines in the order of direction.lines, each padded with
// absent samples to the longest).
IntervisibilityLines intervisibilityLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                                  const PreparedHeights& prepared,
                                                  const TreeDirection& direction,
                                                  const HullTreeTuning& tuning = {});

}  // namespace hfvis::detail
