// horizon_angle_error.hpp: "ask for an error" for the horizon angles themselves
// (HorizonOptions::max_error with HorizonOutputs::horizon_angles): the error K controls, its
// estimate from the run's own planes, and the runs that choose K.
//
// The horizon output is K planes of elevation angle at the azimuths the sweep used
// (HorizonResult::azimuths: lattice steps within the azimuth tolerance of phi_k). Each is exact
// along its own ray (for the samples per unit given), so what K controls is the horizon as a
// function of azimuth: reconstructed from the K directions by periodic linear interpolation
// between their real azimuths, against the true horizon at every azimuth. Its error at a pixel
// is the mean over azimuth of |reconstruction - truth|; the field's, the mean of that over the
// pixels with data (radians).
#pragma once

#include <functional>
#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis::detail {

// The directions of `azimuths` in ascending azimuth (in [0, 2 pi)), each step once (directions
// snapped to one lattice step share its azimuth and plane), and the azimuths so ordered.
struct AzimuthOrder {
  std::vector<int> index;        // into the result's planes
  std::vector<double> azimuth;   // radians in [0, 2 pi), strictly ascending
};
AzimuthOrder azimuthOrder(const std::vector<double>& azimuths);

// Per pixel, the skip-one and skip-two interpolation errors of the horizon planes of `result`:
// each direction against the linear interpolation, at its azimuth, of its neighbours one (and
// two) places away in azimuth order, weighted by the span the interpolation crosses, so that
// skip_one is the mean over azimuth of the midpoint errors of the two interleaved half sets
// (K / 2 directions each), skip_two that of the four quarter sets (radians; NaN at nodata). Needs
// at least five distinct azimuths.
struct SkipErrors {
  std::vector<float> skip_one, skip_two;
};
SkipErrors horizonSkipErrors(const HorizonResult& result);

// The convergence order p the field's skip errors show (the quarter sets' error over the half
// sets', as 2^p), within kHorizonOrderLow .. kHorizonOrderHigh: what the error falls by from K / 2
// to K (1 where the horizon jumps between directions, 2 where it bends smoothly; below 1 before K
// resolves the field's features).
double horizonErrorOrder(const SkipErrors& skips);
constexpr double kHorizonOrderLow = 0.3, kHorizonOrderHigh = 2.0;

// The error estimate of a run's horizon angles (HorizonOutputs::error_estimate with
// horizon_angles): per pixel kHorizonEstimateFactor * skip_one * 2^-p (p the pixel's own order),
// into result.error_estimate (radians, NaN at nodata), and its mean over the pixels with data
// into result.estimated_error, where 2^-p is the pixel's own skip-one error over its skip-two
// error, clamped to the orders kHorizonOrderLow .. kHorizonOrderHigh. 2/3 is the mean of a linear
// interpolation's error over an interval against its midpoint's, for a kink and for a jump alike;
// the factor 1.125 beyond it is calibrated against dense runs of the benchmark's contents
// (bench/report/error_target.md: without it the error was up to 1.09 times the estimate).
void estimateHorizonAngleError(HorizonResult& result);
constexpr double kHorizonEstimateFactor = 2.0 / 3.0 * 1.125;

// The mean over the pixels with data of a pixel's mean over azimuth of |the periodic linear
// interpolation of `result`'s planes between its azimuths - `reference`'s planes|, at the
// reference's azimuths, each weighted by its half gaps (radians): the error of `result` against a
// run of the same sweep at a dense K. Both must hold horizon angles of one field.
double horizonAngleErrorAgainst(const HorizonResult& result, const HorizonResult& reference);

// The mean over the pixels with data of a per-pixel plane (NaN: no data); 0 when none has.
double meanWithData(const std::vector<float>& plane);

// The sweep's work at K per receiver (its directions' samples per period summed, as
// HorizonResult::samples_per_receiver counts a whole-field run; the naive method: K).
double horizonWork(const HeightField& field, const HorizonOptions& options, const HorizonOutputs& outputs, int K);

// The K to run for a need of `needed` directions: of the multiples of 8 from `needed` (rounded up)
// to kHorizonChoiceSpan times it, the one of least work (the sweep's cost is not monotone in K:
// directions near simple slopes take short steps, so K = 64 costs less than K = 40 at the default
// tolerance); ties to the smallest.
int cheapestDirections(int needed, const std::function<double(int)>& work);
constexpr double kHorizonChoiceSpan = 1.25;

// A run of the horizon angles at K with its estimate: a fresh one (`from` null), or one that
// extends `from`, the result of a run at K / m (m >= 2), by the directions it lacks: with exact
// azimuths (the horizon angles' absolute tolerance) a direction's lattice step depends on its
// azimuth alone, and K / m's azimuths are every m-th of K's, so one run of the directions between
// them holds the rest (extendHorizonRun). Takes `from`'s planes.
using HorizonAnglesRun = std::function<HorizonResult(int directions, HorizonResult* from)>;

// HorizonOptions::max_error for the horizon angles: run(K) with the estimate at
// kHorizonFirstDirections, then at kHorizonSecondDirections (the two cost a few per cent of any
// later run: the axes and diagonals, then steps of at most a few pixels), then at the K the
// estimates predict (the error falling as K^-p, p measured between the last two runs within
// 0.5 .. 3), 5 % more, at most kHorizonMostStep times the last K (kHorizonThirdStep times the second's:
// the fall from the first two predicts badly far off): of the multiples of 8 within
// kHorizonChoiceSpan of that, the cheapest by `work`, or the least multiple of the last K that
// reaches it, extending the last run, where the directions it adds cost less (so the runs on the
// way are not cast again, for a K up to twice the need and, while a run extends, the planes of the
// directions it adds held beside the result's: up to 1.75 times a fresh run's, m <= 4; `extend`
// false: never), until the estimate's mean is at most max_error (and never past
// kMaxAutoDirections). Throws InvalidArgument (E in degrees) when a prediction within one such
// step, a fall as K^-3, or the run at kMaxAutoDirections itself needs more than
// kMaxAutoDirections. Edge pixels count as they are: the directions whose rays leave the field at
// once hold -pi/2, and the interpolation between such a direction and its neighbours counts as
// error there (on small fields a visible share).
HorizonResult runHorizonAnglesToError(double max_error, const HorizonAnglesRun& run,
                                      const std::function<double(int)>& work, bool extend = true);

// Some of the directions of a run at `of`: those at `indices`, in that order, each with the
// azimuth and lattice step a run at `of` gives it (the sweep's horizon planes alone). One run of
// the directions an extension adds (extendHorizonRun).
struct DirectionSubset {
  int of = 0;
  std::vector<int> indices;
};

// Runs the horizon operation (src/ops/horizon.cpp) over `subset` of the directions of a run at
// subset.of, with `options` otherwise (options.directions is not looked at): result direction i
// is subset.indices[i]. The sweep's horizon angles (and distances) alone; for extendHorizonRun and
// its tests.
HorizonResult computeHorizonDirections(const ComputeContext& context, const HeightField& field,
                                       const HorizonOptions& options, const HorizonOutputs& outputs,
                                       const DirectionSubset& subset);

// The horizon angles (and distances) of a run at `directions` (a multiple m >= 2 of from's K)
// from `from` and one run of the directions between its own: run(indices) casts, of the
// directions of a run at `directions`, those at `indices` (every one but each m-th), as that run
// casts them, its direction i being indices[i] (its other fields set as a run sets them). Its
// planes are put in their places. So the planes and azimuths are a run's at `directions`, where
// each direction's step depends on its azimuth alone (the sweep's exact azimuths).
// samples_per_receiver: the one run's alone. The estimate is not taken.
HorizonResult extendHorizonRun(HorizonResult from, int directions,
                               const std::function<HorizonResult(const std::vector<int>& indices)>& run);
constexpr int kHorizonFirstDirections = 8, kHorizonSecondDirections = 16;
constexpr double kHorizonMostStep = 4.0, kHorizonThirdStep = 2.0;

}  // namespace hfvis::detail
