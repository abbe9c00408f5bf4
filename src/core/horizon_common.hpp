// horizon_common.hpp: what the device path and the scalar reference of the horizon
// operation share: direction geometry and the final reduction step.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/lattice_geometry.hpp"
#include "core/sweep_geometry.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis::detail {

// Whether a run's directions are exact azimuths (per-direction planes requested) rather than
// quadrature directions.
bool exactAzimuths(const HorizonOutputs& outputs);

// The sweep directions of a run: exact azimuths (within options.azimuth_tolerance) when
// per-direction planes are requested, quadrature directions otherwise.
std::vector<LatticeDirection> horizonDirections(const HeightField& field, const HorizonOptions& options,
                                                const HorizonOutputs& outputs);

// The unit normal (x along +column, y along +row, z up) at pixel (c, r) of prepared heights h:
// surface_normal_sum (kernels/shared/surface_normal.cl, ambient occlusion's normal) normalised;
// (0, 0, 1) when no quad is left.
void pixelNormal(const std::vector<float>& h, int width, int height, int c, int r, float cell_x, float cell_y,
                 float* n);

// sin(pi weight) / pi: the factor of the ambient-occlusion swath of a direction of that
// weight (ambient_term in kernels/horizon.cl), computed once per direction on the host.
float swathFactor(float weight);

// Turns the accumulated sums into the outputs: svf = 1 - weighted sum; ao is the sum itself; each
// clamped to 0 .. 1.
void finishReduction(HorizonResult& result);

// The directions of HorizonOptions::max_error's first run.
constexpr int kFirstAutoDirections = 16;

// The error estimate (HorizonOutputs::error_estimate) from the sums of the even-numbered
// directions in `result` (sky-view factor and occlusion, before finishReduction) and those of the
// odd-numbered ones, the directions' weights summed by half: fills error_estimate and
// estimated_error, and leaves the two sums' total in `result`. The occlusion's part adds its own
// bias, which the halves share (swathBias), from each pixel's tilt (its normal, pixelNormal, over
// `prepared`: the field's prepared heights) and `square_weight`, the directions' squared weight
// averaged over the circle (sum w^3 / sum w).
void splitErrorHalves(HorizonResult& result, const std::vector<float>& odd_svf,
                      const std::vector<float>& odd_ao, double even_weight, double odd_weight,
                      const HeightField& field, const std::vector<float>& prepared, double square_weight);

// The bias of Timonen & Westerholm's Eq. 5 (ambient_term), which takes the horizon as constant
// over each direction's swath of azimuth while integrating the normal's cosine over it exactly,
// where the horizon varies smoothly over azimuth: over a plane that sees all the sky above its
// tangent plane, (pi^2 / 6) w^2 sin^2(tilt) for swaths of weight w (`square_weight`: w^2, or the
// mean of w^2 over the circle where the weights differ; the occlusion 0.0023 short
// of 1 at K = 16 for a tilt of 37 degrees, 0.0094 at K = 8: the order K^-2 of a product rule).
// The even and the odd directions carry it alike, so their difference does not show it (it was
// 3e-5 there, and --max-error stopped at K = 16 with the error 80 times its estimate: a probe's
// find). Taken 1.15 times: runToError divides a raw estimate by up to 1.14 (richardsonDivisor),
// which is meant for the halves' part alone.
double swathBias(double sin2_tilt, double square_weight);

// HorizonResult::estimated_error of a per-pixel error estimate: its 99th percentile over the
// pixels with data (not NaN), 0 when none has.
double estimatedError(const std::vector<float>& estimate);

// The directions runForMaxError (intervisibility's and the environment light's maximum error) asks
// for after a run at `directions` whose estimate was `estimated`, the run before it at `earlier` directions with `earlier_estimate` (0 for none):
// the estimate falls as K^-p, p measured from the two runs (within 0.5 .. 3; from one run 1, and
// then at most 4 times the directions: smooth fields fall much faster, bench/report/error_target.md),
// so K (estimated / max_error)^(1/p), 5 % more, rounded up to a multiple of 8, and at least 8 more.
int directionsForError(int directions, double estimated, int earlier, double earlier_estimate, double max_error);

// One run of HorizonOptions::max_error's sky-view factor and occlusion, as the choice of K sees a
// tile (or the whole field): its K and the 99th percentile over the tile's pixels of its raw error
// estimate (half the even and odd halves' difference, splitErrorHalves).
struct EstimateRun {
  int directions = 0;
  double raw = 0.0;
};

// The order p at which the raw estimate falls with K (raw ~ K^-p), measured between the last of
// `runs` (ascending K) and the latest earlier run of at most half its K, within
// 1 .. kMaxRichardsonOrder; 1 when there is none (a single run, or only nearer ones: too near to
// measure).
double estimateOrder(const std::vector<EstimateRun>& runs);

// What the raw estimate is divided by to estimate the error of the K result itself: the raw
// estimate is about |r(K/2) - r(K)| (the even half is a K / 2 quadrature), and with an error
// falling as K^-p, of one sign, that is (2^p - 1) times the error at K (Richardson). 1 at p = 1
// (then the estimate stays the halves' difference). p is kept at most kMaxRichardsonOrder, a
// divisor of 1.14: the raw estimate lies 1.1 to 4 times above the error against a dense run on
// the benchmark's contents (bench/report/error_curve.md), but on white-noise heights barely above
// it while falling as fast: the fall does not tell them apart, and with p allowed up to 1.5 the
// noise field of HorizonMaxError.MeetsTheTargetAgainstADenseRun met E by the estimate and missed
// it by the error at E = 0.05, 0.01 and 0.005.
constexpr double kMaxRichardsonOrder = 1.1;
double richardsonDivisor(double order);

// A run's K aims at this share of the maximum error, so that a prediction a little short does not
// take another run.
constexpr double kErrorAim = 0.9;

// The K HorizonOptions::max_error's sky-view factor and occlusion run next after `runs` (ascending,
// the last not meeting max_error by its estimate, raw / richardsonDivisor(estimateOrder)): the K
// where that estimate would meet kErrorAim times max_error, the raw estimate falling as K^-q, q
// measured between the last two runs within 1 .. 2 (from the first run alone 1). Where that K is
// more than 4 times the last run's, the next run is a probe at the larger of twice the last K and
// a sixth of it, so that the final run is predicted from a run nearer it (the fall steepens with
// K on the benchmark's contents: a far prediction overshoots) while the probes cost little beside
// it (bench/error_target_replay.py replays such rules on the fixed-K curves). Rounded up to a
// multiple of 8, at least 8 more than the last K. `predicted`: the K predicted to meet max_error
// itself (from the first run alone at q = 2, the fastest fall it assumes: a bound), beyond
// kMaxAutoDirections capped at twice it, which the caller refuses.
struct NextErrorRun {
  int directions = 0;
  int predicted = 0;
};
NextErrorRun nextDirectionsForError(const std::vector<EstimateRun>& runs, double max_error);

// The InvalidArgument a maximum error gets when a run at `directions` whose estimate was
// `estimated` (`where`, e.g. in which tile) predicts `next` directions, beyond kMaxAutoDirections.
InvalidArgument beyondAutoDirections(double max_error, int next, int directions, double estimated,
                                     const std::string& where = "");

// A maximum error's runs for an operation other than the horizon sweep's (intervisibility, the
// environment light): run(K) at K = kFirstAutoDirections, then at directionsForError's K, at most 4
// times the last K (a prediction beyond kMaxAutoDirections refused only from near), until a result's
// estimated_error is at most max_error; that result with `runs` (the K of each run) set.
// Throws beyondAutoDirections' error.
template <class Result, class Run>
Result runForMaxError(double max_error, const Run& run) {
  int directions = kFirstAutoDirections, earlier = 0;
  double earlier_estimate = 0.0;
  std::vector<int> runs;
  for (;;) {
    Result result = run(directions);
    runs.push_back(directions);
    if (result.estimated_error <= max_error) {
      result.runs = std::move(runs);
      return result;
    }
    const int wanted =
        directionsForError(directions, result.estimated_error, earlier, earlier_estimate, max_error);
    // Refused where the prediction is near enough to trust (within kMostStep times the last K),
    // where even a fall as K^-3 would need more, or where the last run took the most directions.
    // A prediction farther off is a run kMostStep times as far, which measures the fall again: a
    // 99th percentile can fall off a cliff (the environment's sun misplaces its shadows' edges at a
    // few per cent of the pixels, then at none), so a fall measured before it predicts badly.
    constexpr int kMostStep = 4;
    const double fastest = directions * std::cbrt(result.estimated_error / max_error);
    if (wanted > kMaxAutoDirections && (wanted <= kMostStep * directions ||
                                        directions >= kMaxAutoDirections || fastest > kMaxAutoDirections))
      throw beyondAutoDirections(max_error, wanted, directions, result.estimated_error);
    const int next = std::min({wanted, kMostStep * directions, kMaxAutoDirections});
    earlier = directions;
    earlier_estimate = result.estimated_error;
    directions = next;
  }
}

// Whether the field has per-row spacing (HeightField::row_cell_size_x/y): positions along the
// sweep's lines (in whole units) and the naive march's rays are then ground lengths summed step by step.
bool hasRowSpacing(const HeightField& field);

// A field with per-row spacing (HeightField::row_cell_size_x/y), as horizon_lattice takes it
// (HFVIS_ROW_SPACING), one table per direction: per row r, the ground length of the period
// from a receiver in row r to the next one along +(a, b) (the cell sizes at its middle row
// r + b / 2, linear between rows) in whole units of sweepUnit(field), at least 1, and its terms:
// unit ground direction (x, y), quadrature weight and swath factor there. Positions along a line
// are sums of whole units: exact in float (below 2^24), whichever receiver a sum starts from, so
// a field cut from a larger one (HeightField::origin), whose rows' lengths and terms are the
// larger field's (its rows are read), starts each line at the larger field's position
// (lineStartPosition) and meets every sample where the larger field does. The step's ground
// azimuth turns with the spacing, so with `quadrature` (sky-view factor, occlusion) the weights
// are the half gaps between the steps' azimuths at that row (setQuadratureWeights); otherwise each
// keeps its own (1/K). Both the kernel and the reference get these floats.
struct RowTable {
  std::vector<float> length;  // one per row (rayRowTables: ground length per pixel along the ray)
  std::vector<float> terms;   // four per row: cos, sin, weight, swath
  // b != 0: per row R of the larger field (of this one without an origin), the units of the
  // periods from receivers in rows R, R + b, R + 2 b ... inside it, modulo 2^32 (a steep step
  // sums far more than a line's: the difference of two, a line's part, is exact); empty otherwise.
  std::vector<std::uint32_t> beyond;
};
std::vector<RowTable> latticeRowTables(const HeightField& field, const std::vector<LatticeDirection>& directions,
                                       bool quadrature, bool parity_apart = false);

// The position, in units, of receiver (col, row) of this field, the first of its line of step
// (a, b) here, along the line through the larger field (HeightField::origin; 0 without one: a
// line starts at its far end): the units of the periods from it to that line's far end, as
// horizon_lattice's line_start_position computes them (`table`: latticeRowTables').
float lineStartPosition(const HeightField& field, const RowTable& table, int a, int b, int col, int row);

// The same for the naive march (horizon_naive with HFVIS_ROW_SPACING), one table per ray
// direction: per row r, the ground length per pixel along the ray with row r's cell sizes, and
// its terms there (its weight the half gaps between the rays' azimuths at that row).
std::vector<RowTable> rayRowTables(const HeightField& field, const std::vector<SweepDirection>& rays);

// An empty result with the requested planes allocated (NaN-filled).
HorizonResult allocateResult(const HeightField& field, const HorizonOptions& options,
                             const HorizonOutputs& outputs);

}  // namespace hfvis::detail
