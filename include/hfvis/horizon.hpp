// hfvis/horizon.hpp: horizon maps (elevation angles and distances per direction), and in the
// same sweep any of the outputs that integrate them over azimuth: the sky-view factor, ambient
// occlusion (hfvis/sky_view_factor.hpp and hfvis/ambient_occlusion.hpp ask for one alone) and
// an environment's irradiance.
//
// Directions follow hfvis/sweep_options.hpp. The horizon of receiver p in direction k
// is the largest elevation angle atan2(h(q) - h(p), ground distance) over surface
// samples q on the ray from p, in radians; -pi/2 where the ray leaves the field at once.
#pragma once

#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/environment_map.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis {

enum class HorizonMethod {
  Sweep,  // convex-hull-stack sweep along lines through the pixel centres (Timonen & Westerholm 2010)
  Naive,  // per-pixel ray march, bilinear samples: the O(N^3) baseline and oracle
};

struct HorizonOptions : SweepOptions {
  HorizonMethod method = HorizonMethod::Sweep;
  // Sweep only. The sweep runs along primitive integer steps (a, b), so that every receiver
  // lies on a line through its own centre (see docs/ALGORITHMS.md). When the
  // per-direction planes are requested, direction k is the cheapest step whose azimuth is
  // within this many radians of phi_k (the closest one when none is; steps up to 64
  // pixels, and for a single direction, K = 1, up to 4096 where no shorter one is within);
  // HorizonResult::azimuths gives the azimuths used. Sky-view factor, ambient occlusion and
  // the environment's irradiance alone integrate over azimuth: they take the cheapest step
  // within half the spacing 2 pi / K of phi_k, weighted by the share of the circle it stands for.
  // samples_per_unit S: the sweep samples every grid-line crossing of a receiver's ray
  // (exact heights of the bilinear surface) and, for S > 1, about S points per pixel length
  // between crossings. Default: 0.25 degrees.
  double azimuth_tolerance = 0.25 * 3.14159265358979323846 / 180.0;
  // Sweep only. Rows per strip: a field whose heights, sums and planes do not fit the memory
  // budget at once runs in horizontal strips, each line's hull stack carried from strip to
  // strip, so the results equal a whole-field run bit for bit. 0: the whole field when it fits,
  // else as many rows as half the budget holds; fewer rows than the field's force strips.
  // The naive method needs the whole field.
  int strip_rows = 0;
  // Ask for an error, not a direction count: when > 0, the sky-view factor and occlusion (alone,
  // no planes or environment) choose K themselves (options.directions is ignored), so that the
  // 99th percentile of the error estimate (HorizonResult::estimated_error) is at most max_error,
  // in their own unit (absolute, both lie in 0..1); HorizonResult::directions says which K. The
  // estimate is then that of the K result itself: the halves' difference (error_estimate below)
  // divided by 2^p - 1 (Richardson: the difference is about |r(K/2) - r(K)|), p the order at which
  // it fell (as K^-p) between this run and an earlier one of at most half its K, within 1 .. 1.1
  // (1 when there is none: the difference itself; HorizonResult::richardson_divisor_least/most).
  // A first run at 16 directions and each one after it predicts the K where the estimate meets
  // 0.9 max_error (the fall measured from the last two runs); a prediction more than 4 times the
  // last K takes a probe first (twice the last K, or a sixth of the prediction), until the
  // estimate is met. Throws InvalidArgument, naming the K it would take, when a run predicts more
  // than kMaxAutoDirections (after the first run only when even a fall as K^-2 would). The
  // samples per unit stay as given.
  // With the horizon planes (angles alone, or with their distances; no sky-view factor, occlusion
  // or environment in the same run), max_error is in radians, 0 < max_error < pi/2, and bounds the
  // mean horizon angle error: over the pixels with data and over azimuth, |the K planes
  // interpolated linearly in azimuth between their real azimuths (HorizonResult::azimuths) - the
  // true horizon| (each plane is exact along its own ray for the samples per unit given, so this
  // is the error K controls). Its estimate (HorizonResult::estimated_error, the mean; per pixel
  // error_estimate) comes from the run's own planes: each direction against the interpolation of
  // its neighbours in azimuth (the error of the K / 2 reconstruction at their midpoints), scaled to
  // K by 2/3 (an interval's mean interpolation error against its midpoint's) times 1.125
  // (calibrated) and by 2^-p, p the order the pixel's neighbours two places away show (within
  // 0.3 .. 2; src/core/horizon_angle_error.hpp). Runs at 8 and 16 directions,
  // then at the K the last two estimates predict (5 % more, at most 4 times the last K and the third
  // run at most twice the second's, the least
  // work within 1.25 times that, or, where the directions it adds cost less, the least multiple of
  // the last K reaching it, which extends that run: its planes kept, the directions between them
  // run; the planes those of a run at that K); one K for the whole field (error_tile refused).
  // bench/report/error_target.md measures it against K = 2048.
  double max_error = 0.0;
  // With max_error, where the field needs them: after the first run (the whole field at 16
  // directions), while the estimate's 99th percentile over the field exceeds max_error, the tiles
  // of error_tile x error_tile pixels with the most pixels above it (until those left hold at most
  // half the pixels the percentile lets above it) run again, each at the next K its own runs
  // choose as the whole field's do (the prediction, or a probe toward a far one), sweeping only
  // the lines that reach them (each cut after its last receiver there, the horizons still from the
  // whole line beyond). A pixel's values are those of the whole-field run at its tile's last K, bit
  // for bit (HorizonResult::pixel_directions), its estimate over its tile's divisor. 0, the
  // default: the whole field takes one K. On the benchmark's contents refinement cost more work
  // than one K for the whole field (bench/report/error_target.md: a tile's run also sweeps its
  // lines' whole upstream, and each tile steps through runs of its own). At least kMinErrorTile:
  // a tile of a few pixels stops when their estimates happen to lie low, and the field's error
  // then exceeds E (a tile of 1 on a 256^2 city DSM: 5x E; tiles of 8 .. 32 met it; orientation, a throwaway
  // comparison with K = 2048).
  int error_tile = 0;
};

// The least HorizonOptions::error_tile (pixels a side) taken.
constexpr int kMinErrorTile = 16;

// The most directions max_error may choose.
constexpr int kMaxAutoDirections = 4096;

// The K max_error's runs take, ascending: multiples of 8 about 12-25 % apart, from 8 to
// kMaxAutoDirections (a tile's predicted K is rounded up to the next one, so that tiles of about
// the same need share a run).
std::vector<int> directionLadder();

// What to compute; only what is asked for is stored or reduced.
struct HorizonOutputs {
  bool horizon_angles = false;     // K channels of elevation angle, radians
  bool horizon_distances = false;  // K channels of ground distance to the horizon point
  bool sky_view_factor = false;    // 1 - sum_k w_k sin(max(0, elevation_k)), w_k the directions' weights
  bool ambient_occlusion = false;  // Eq. 5 of Timonen & Westerholm 2010, uniform sky of
                                   // radiance 1, normalised so a flat plane gives 1
  // The irradiance from this environment (hfvis/environment_light.hpp), one plane per channel; null:
  // none. The map must outlive the call. Not on latitude / longitude grids (per-row spacing).
  const EnvironmentMap* environment = nullptr;
  // With the sky-view factor or occlusion alone (no planes, no environment; K >= 2): an estimate of
  // their error against the azimuthal integral they approximate (HorizonResult::error_estimate),
  // from the same run at the cost of one more sum per pixel. With the horizon angles alone (their
  // distances may come along; K >= 5): the estimate of their mean error (HorizonOptions::max_error)
  // at the K given, computed on the host from the planes.
  bool error_estimate = false;
};

struct HorizonResult {
  int width = 0;
  int height = 0;
  int directions = 0;
  std::vector<double> azimuths;          // azimuth of each direction as computed, radians
  std::vector<float> angles;             // directions planes of width*height, if asked
  std::vector<float> distances;          // same layout; 0 where no point casts a horizon or the
                                         // surface's own slope at the receiver is the horizon
  std::vector<float> sky_view_factor;    // width*height, if asked
  std::vector<float> ambient_occlusion;  // width*height, if asked
  std::vector<float> irradiance;         // the environment's channels' planes of width*height, if asked
  // With HorizonOutputs::error_estimate or HorizonOptions::max_error, per pixel: half the difference
  // between the results of the even- and the odd-numbered directions alone (each half's sum over
  // its own weights: two interleaved quadratures of K / 2 directions), occlusion's plus the bias
  // its swaths share, which the difference cannot show (detail::swathBias: (pi^2 / 6) w^2
  // sin^2(tilt) times 1.15), the larger of the sky-view factor's and occlusion's; NaN at nodata.
  // With max_error divided by the Richardson divisor
  // 2^p - 1 (1 .. 1.14) its runs measured, per tile (HorizonOptions::max_error); a run at a K of
  // your own keeps the difference itself. Measured against the dense azimuthal integral, on the
  // benchmark's contents the difference lies 1.1 to 4 times above the K result's error
  // (bench/report/error_curve.md), on white-noise heights barely above it
  // (tests/test_horizon_error_target.cpp): the divisor is kept that small for them.
  // With the horizon angles: per pixel the estimated mean over azimuth of the K planes'
  // interpolation error, radians (HorizonOptions::max_error).
  std::vector<float> error_estimate;
  double estimated_error = 0.0;  // its 99th percentile over the pixels with data (horizon angles: its
                                 // mean); 0 without it
  // With HorizonOptions::max_error: the K of each run it made, in order (with error_tile, runs
  // after the first cover only the tiles that needed them; with the horizon angles a run may
  // extend the one before, casting only the directions it adds: samples_per_receiver is the
  // cost of them all); empty otherwise. `directions` is then the largest K any pixel took, and `azimuths`
  // that run's.
  std::vector<int> runs;
  // With HorizonOptions::max_error, per pixel: the K of the run its values (and estimate) come from.
  std::vector<int> pixel_directions;
  // With HorizonOptions::max_error (sky-view factor, occlusion): the least and the most Richardson
  // divisor 2^p - 1 the raw estimate was divided by, over the tiles (equal with one tile); 0
  // otherwise (the horizon planes' estimate has none).
  double richardson_divisor_least = 0.0, richardson_divisor_most = 0.0;
  // The sweep's work, all runs together (with max_error; else this run's): per receiver of the
  // field, the samples of each direction's period times the receivers on the lines it swept
  // (a whole-field run at K: its directions' samples per period summed; 0 for the naive method).
  double samples_per_receiver = 0.0;
};

// Throws InvalidArgument for bad sweep options (see sweep_options.hpp) or when no output
// is requested.
void validate(const HorizonOptions& options, const HorizonOutputs& outputs);

// Runs options.method on the device of `context`.
HorizonResult computeHorizons(const ComputeContext& context, const HeightField& field,
                              const HorizonOptions& options, const HorizonOutputs& outputs);

}  // namespace hfvis
