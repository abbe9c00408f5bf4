// hfvis/intervisibility.hpp: visibility between all points of a height field: for every
// receiver, the number of surface samples it sees summed over K azimuthal directions, the
// visible ground area estimated from them ("total viewshed"), and the convex hull tree's
// statistics (Timonen 2013, Table 2).
//
// Directions follow hfvis/sweep_options.hpp. Along direction k, receiver p sees the
// surface samples q = p + i * step * d_k, i >= 1, inside the field (bilinear heights,
// nodata samples absent). The naive march takes d_k at phi_k and step 1 / S (S =
// samples_per_unit). The hull tree runs on lattice lines through the pixel centres: d_k is
// the cheapest integer step (a, b) within half the spacing 2 pi / K of phi_k, standing for
// phi_k's wedge of azimuth (weight 1 / K, as the naive march's rays), and the step
// |(a, b)| / ceil(|(a, b)| S), at most 1 / S, so every receiver is a sample of its own line at
// its own height (docs/ALGORITHMS.md); between two of its samples, the surface's point that
// rises farthest above their chord (a crossing or a concave cell piece's, where it rises above
// it: a one-pixel wall, roofs touching at a corner) hides too, but is not counted. Tie rule: q
// is visible when its slope from p is >= the slope of every sample (and such peak) strictly
// between them (grazing samples are visible; on a flat plane every sample is). The samples'
// rounding is forgiven: a hidden q is visible too where the steepest sample (or peak) between
// hides it only within that rounding (2^-22 of the sum of the heights compared, counted from the
// field's heightBase, and of the highest one's absolute value), as it does every hidden sample
// between them, so on a tilted plane every sample is visible as well (docs/ALGORITHMS.md,
// "Grazing samples and the heights' rounding"). Every decision is an exact sign, so the sweep,
// the naive march and brute force agree sample for sample on identical samples.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis {

enum class IntervisibilityMethod {
  HullTree,  // convex hull tree sweep on lattice lines, one work-item per line (Timonen 2013, Algorithm 1)
  Naive,     // per-pixel visibility march, bilinear samples: the O(N^3) baseline and oracle
};

// How the convex hull tree sweep does its work. Every setting builds the same trees and gives
// the same results (horizons, counts, areas, bounce); they change only the work done: the
// convexity checks t and the links written (bench/report/REPORT.md measures the time and t
// of each).
struct HullTreeTuning {
  // The walk keeps the old root's level in registers and writes a link only where it
  // changes (the aim of Timonen 2013's Algorithm 2: postponed, consolidated linkage
  // writes). false = Algorithm 1's walk as written, every relink stored at once.
  bool deferred_writes = true;
  // The old root's last child is checked first (Sec. 7): when it fails every child fails,
  // the old root is replaced and the children's own checks are skipped; when it passes the
  // old root stays. Needs deferred_writes (it works inside that walk).
  bool replacement_check = true;
  // The safe zone (Sec. 7, Algorithm 3): a replaced old root whose children stay as they are
  // (the new sample lies in the zone below every child's edge to its first child) skips the
  // walk. Needs replacement_check. Off by default: it skips up to two thirds of the walks
  // but showed no measurable gain in time on a CPU (bench/report/REPORT.md). Not taken on
  // fields with per-row spacing (latitude / longitude grids), whose steps differ in length.
  bool safe_zone = false;
  // Steps past the receiver one safe zone covers before it is recomputed: a power of two,
  // 1 .. 4096.
  int safe_zone_steps = 16;
};

// The named tunings the CLI (--hull-tree) and the benchmark offer: "plain" (Algorithm 1 as
// written: every option off), "deferred" (deferred_writes only), "default" (HullTreeTuning{})
// and "zone" (the default with the safe zone). std::nullopt for any other name.
std::optional<HullTreeTuning> hullTreeTuningNamed(const std::string& name);

struct IntervisibilityOptions : SweepOptions {
  IntervisibilityMethod method = IntervisibilityMethod::HullTree;
  HullTreeTuning tree;  // HullTree only
  // HullTree only. Rows per strip: a field whose heights and sums do not fit the memory budget
  // beside one line's tree runs in horizontal strips, each line's tree kept on the device from
  // strip to strip (only the strip's heights and sums are), so the results equal a whole-field
  // run bit for bit. 0: the whole field when it fits, else as many rows as half the budget
  // holds; fewer rows than the field's force strips. The naive method needs the whole field.
  int strip_rows = 0;
  // HullTree only. Ask for an error, not a direction count: when > 0 (and < 1), K is chosen
  // (options.directions is ignored) so that the 99th percentile over the pixels of the error
  // estimate (IntervisibilityResult::estimated_error) of the visible count, relative to the
  // field's mean count, is at most max_error (the area is not estimated): a first run at 16
  // directions, each run predicting the K the next needs (the estimate falling as K^-p, p measured
  // from the last two runs), at most 4 times the last K, until the estimate meets it;
  // IntervisibilityResult::directions and ::runs say which K. Throws InvalidArgument, naming the
  // K it would take, when a run predicts more than kMaxAutoDirections (hfvis/horizon.hpp) from
  // within 4 times its K, or even a fall as K^-3 would need more, or the run at kMaxAutoDirections
  // misses it (a far prediction runs 4 times as far first). The samples per unit stay as given.
  double max_error = 0.0;
};

// What to compute; only what is asked for is stored or reduced.
struct IntervisibilityOutputs {
  // Visible samples summed over the K directions, per pixel, counted at samples_per_unit
  // S per pixel length: each visible sample counts step * S (1 for the naive march; the
  // tree's steps are at most 1 / S), so a direction's count is its visible length along
  // the ray in units of 1 / S pixel. Each pixel is the receiver of its own line: no
  // interpolation between lines.
  bool visible_count = false;
  // Visible ground area, in ground units squared: each visible sample at ground distance
  // rho stands for D * rho * drho, drho the ground step along the direction and D its wedge
  // of azimuth (2*pi/K, for the naive march and the tree; a tree step that K' of the phi_k
  // share, at very large K, stands for K' wedges): the ring sector it represents around the
  // receiver.
  bool visible_area = false;
  // Horizon and iteration totals of the hull tree (HullTree only).
  bool statistics = false;
  // HullTree only, K >= 2: an estimate of the count's error against the azimuthal integral it
  // approximates, relative to the field's mean count (IntervisibilityResult::error_estimate), from
  // the same run: the even- and the odd-numbered directions summed apart.
  bool error_estimate = false;
};

// Totals over every sample of every line of every direction (line samples, not pixels: a
// statistics run reads every sample's horizons, as Timonen 2013's Table 2 counts them).
struct IntervisibilityStatistics {
  std::uint64_t receivers = 0;         // present line samples, each a receiver once
  std::uint64_t lines = 0;             // lines with at least one present sample
  std::uint64_t horizons = 0;          // sum of m_i: distinct visibility horizons
  std::uint64_t iterations = 0;        // sum of t_i: convexity checks made (Algorithm 1's with
                                       // hullTreeTuningNamed("plain"), fewer by default)
  std::uint64_t visible_samples = 0;   // sum of visible samples (Table 1's p_a * receivers)
  std::uint64_t naive_iterations = 0;  // samples the naive method would test on the same lines
  std::uint64_t lines_over_bound = 0;  // lines where t > 2m + n (Section 6 proves none)
  std::uint64_t safe_zone_skips = 0;   // receivers whose tree update skipped the walk

  double meanHorizons() const { return receivers ? double(horizons) / receivers : 0.0; }      // m_a
  double meanIterations() const { return receivers ? double(iterations) / receivers : 0.0; }  // t_a
  double meanVisible() const { return receivers ? double(visible_samples) / receivers : 0.0; }
  double meanNaiveIterations() const { return receivers ? double(naive_iterations) / receivers : 0.0; }
};

struct IntervisibilityResult {
  int width = 0;
  int height = 0;
  int directions = 0;
  std::vector<double> azimuths;          // phi_k, radians
  std::vector<float> visible_count;      // width*height if asked; NaN at nodata receivers
  std::vector<float> visible_area;       // width*height if asked; NaN at nodata receivers
  IntervisibilityStatistics statistics;  // if asked (with max_error: of the last run)
  // With IntervisibilityOutputs::error_estimate or IntervisibilityOptions::max_error, per pixel:
  // the difference between the even- and the odd-numbered directions' counts (each half's sum over
  // its own wedges: two interleaved quadratures of K / 2 directions), relative to the field's mean
  // count (not the pixel's own: in a pit or a street it can be near 0); NaN at nodata. The whole
  // difference, not half of it as for the sky-view factor: the count's azimuthal error falls
  // slowly (about K^-0.6 on noise and a city), so the halves' errors hardly cancel and half their
  // difference lies at the error, not above it. Of the count only: the area, whose far samples
  // weigh most, errs more (2-5x at the same K) and is not estimated. Measured against a dense K in
  // bench/report/error_target.md.
  std::vector<float> error_estimate;
  double estimated_error = 0.0;  // its 99th percentile over the pixels with data; 0 without it
  // With IntervisibilityOptions::max_error: the K of each run it made, in order (the last is
  // `directions`); empty otherwise.
  std::vector<int> runs;
};

// Throws InvalidArgument for a replacement check without deferred writes, a safe zone
// without the replacement check, or a safe_zone_steps that is not a power of two in 1 .. 4096.
void validate(const HullTreeTuning& tuning);

// Throws InvalidArgument for bad sweep options (see sweep_options.hpp), a bad tree tuning,
// no output requested, statistics, an error estimate or a maximum error asked of the naive
// method, a maximum error outside [0, 1) or not finite, an estimate at K < 2, or a negative
// strip_rows (or strips asked of the naive method).
void validate(const IntervisibilityOptions& options, const IntervisibilityOutputs& outputs);

// Runs options.method on the device of `context`. Throws InvalidArgument (bad field or
// options), MemoryBudgetError (one direction does not fit), OpenClError, KernelBuildError.
IntervisibilityResult computeIntervisibility(const ComputeContext& context, const HeightField& field,
                                             const IntervisibilityOptions& options,
                                             const IntervisibilityOutputs& outputs);

}  // namespace hfvis
