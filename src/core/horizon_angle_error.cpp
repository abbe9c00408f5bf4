// horizon_angle_error.cpp: see horizon_angle_error.hpp.
#include "core/horizon_angle_error.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/horizon_common.hpp"
#include "core/lattice_geometry.hpp"
#include "hfvis/errors.hpp"

namespace hfvis::detail {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// The gap from azimuth x up to y going round (radians, in [0, 2 pi)).
double gapUp(double x, double y) {
  const double g = y - x;
  return g < 0.0 ? g + kTwoPi : g;
}

// The plane of direction `k` of `result`.
const float* plane(const HorizonResult& result, int k) {
  return result.angles.data() + static_cast<std::size_t>(k) * result.width * result.height;
}

// Per pixel the interpolation error at each direction of `order` from its neighbours `skip`
// places away, weighted by the span it crosses over skip * 2 * 2 pi (so that, the directions
// evenly spaced, it is the mean of those errors).
std::vector<float> skipError(const HorizonResult& result, const AzimuthOrder& order, int skip) {
  const int n = static_cast<int>(order.index.size());
  const std::size_t pixels = static_cast<std::size_t>(result.width) * result.height;
  std::vector<double> sum(pixels, 0.0);
  for (int i = 0; i < n; ++i) {
    const int before = (i - skip % n + n) % n, after = (i + skip) % n;
    const double g1 = gapUp(order.azimuth[before], order.azimuth[i]),
                 g2 = gapUp(order.azimuth[i], order.azimuth[after]);
    const double span = g1 + g2, weight = span / (2.0 * skip * kTwoPi);
    // (the weights of the interpolation once per direction, not a division per pixel)
    const double to_lo = g2 / span, to_hi = g1 / span;
    const float *h = plane(result, order.index[i]), *lo = plane(result, order.index[before]),
                *hi = plane(result, order.index[after]);
    for (std::size_t p = 0; p < pixels; ++p) {
      const double interpolated = double(lo[p]) * to_lo + double(hi[p]) * to_hi;
      sum[p] += weight * std::abs(double(h[p]) - interpolated);  // NaN at nodata stays NaN
    }
  }
  return std::vector<float>(sum.begin(), sum.end());
}

}  // namespace

AzimuthOrder azimuthOrder(const std::vector<double>& azimuths) {
  std::vector<std::pair<double, int>> sorted;
  for (std::size_t k = 0; k < azimuths.size(); ++k) {
    double a = std::fmod(azimuths[k], kTwoPi);
    if (a < 0.0) a += kTwoPi;
    sorted.emplace_back(a, static_cast<int>(k));
  }
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  AzimuthOrder order;
  for (const auto& [a, k] : sorted) {
    // One lattice step's azimuth is computed once, so its copies are equal (and 2 pi apart at most
    // across zero: those within a hair of the first are the same step going round).
    if (!order.azimuth.empty() && a - order.azimuth.back() < 1e-12) continue;
    order.azimuth.push_back(a);
    order.index.push_back(k);
  }
  while (order.azimuth.size() > 1 && order.azimuth.back() + 1e-12 >= order.azimuth.front() + kTwoPi) {
    order.azimuth.pop_back();
    order.index.pop_back();
  }
  return order;
}

SkipErrors horizonSkipErrors(const HorizonResult& result) {
  const AzimuthOrder order = azimuthOrder(result.azimuths);
  if (order.index.size() < 5)
    throw InvalidArgument("an error estimate of the horizon angles needs at least 5 distinct azimuths (got " +
                          std::to_string(order.index.size()) + ")");
  return {skipError(result, order, 1), skipError(result, order, 2)};
}

double meanWithData(const std::vector<float>& plane) {
  double sum = 0.0;
  std::size_t count = 0;
  for (float v : plane)
    if (!std::isnan(v)) sum += v, ++count;
  return count ? sum / count : 0.0;
}

double horizonErrorOrder(const SkipErrors& skips) {
  const double one = meanWithData(skips.skip_one), two = meanWithData(skips.skip_two);
  if (!(one > 0.0 && two > 0.0)) return kHorizonOrderLow;
  return std::clamp(std::log2(two / one), kHorizonOrderLow, kHorizonOrderHigh);
}

void estimateHorizonAngleError(HorizonResult& result) {
  SkipErrors skips = horizonSkipErrors(result);
  const double low = std::pow(2.0, -kHorizonOrderHigh), high = std::pow(2.0, -kHorizonOrderLow);
  for (std::size_t p = 0; p < skips.skip_one.size(); ++p) {
    const double one = skips.skip_one[p], two = skips.skip_two[p];
    const double fall = two > 0.0 ? std::clamp(one / two, low, high) : high;
    skips.skip_one[p] = static_cast<float>(kHorizonEstimateFactor * one * fall);  // NaN stays NaN
  }
  result.error_estimate = std::move(skips.skip_one);
  result.estimated_error = meanWithData(result.error_estimate);
}

double horizonAngleErrorAgainst(const HorizonResult& result, const HorizonResult& reference) {
  if (result.width != reference.width || result.height != reference.height || result.angles.empty() ||
      reference.angles.empty() || result.azimuths.empty() || reference.azimuths.empty())
    throw InvalidArgument("horizonAngleErrorAgainst: two runs' horizon angles of one field");
  const AzimuthOrder order = azimuthOrder(result.azimuths), dense = azimuthOrder(reference.azimuths);
  const std::vector<double> weights = halfGapWeights(dense.azimuth);
  const std::size_t pixels = static_cast<std::size_t>(result.width) * result.height;
  const int n = static_cast<int>(order.index.size());
  std::vector<double> sum(pixels, 0.0);
  for (std::size_t j = 0; j < dense.index.size(); ++j) {
    const double psi = dense.azimuth[j];
    // The result's directions on either side of psi, going round.
    const int after = static_cast<int>(std::upper_bound(order.azimuth.begin(), order.azimuth.end(), psi) -
                                       order.azimuth.begin()) % n;
    const int before = (after + n - 1) % n;
    const double g1 = gapUp(order.azimuth[before], psi), g2 = gapUp(psi, order.azimuth[after]);
    const double span = g1 + g2;
    const double t = n == 1 || span == 0.0 ? 0.0 : g1 / span;
    const float *lo = plane(result, order.index[before]), *hi = plane(result, order.index[after]),
                *truth = plane(reference, dense.index[j]);
    for (std::size_t p = 0; p < pixels; ++p)
      sum[p] += weights[j] * std::abs(double(lo[p]) * (1.0 - t) + double(hi[p]) * t - double(truth[p]));
  }
  return meanWithData(std::vector<float>(sum.begin(), sum.end()));
}

double horizonWork(const HeightField& field, const HorizonOptions& options, const HorizonOutputs& outputs, int K) {
  if (options.method != HorizonMethod::Sweep) return K;
  HorizonOptions at = options;
  at.directions = K;
  double samples = 0.0;
  for (const LatticeDirection& d : horizonDirections(field, at, outputs))
    samples += static_cast<double>(latticeSamples(d, at.samples_per_unit).size());
  return samples;
}

int cheapestDirections(int needed, const std::function<double(int)>& work) {
  const int first = (std::max(needed, 8) + 7) / 8 * 8;
  const int last = std::min(kMaxAutoDirections, static_cast<int>(std::ceil(first * kHorizonChoiceSpan)));
  int best = first;
  double least = work(first);
  for (int K = first + 8; K <= last; K += 8) {
    const double w = work(K);
    if (w < least) least = w, best = K;
  }
  return best;
}

HorizonResult runHorizonAnglesToError(double max_error, const HorizonAnglesRun& run,
                                      const std::function<double(int)>& work_of, bool extend_runs) {
  // (each K's work once: it builds K's lattice steps, about a millisecond)
  std::map<int, double> known;
  const std::function<double(int)> work = [&](int K) {
    const auto found = known.find(K);
    return found != known.end() ? found->second : known.emplace(K, work_of(K)).first->second;
  };
  int directions = kHorizonFirstDirections, earlier = 0;
  double earlier_estimate = 0.0, total = 0.0;
  std::vector<int> runs;
  HorizonResult result = run(directions, nullptr);
  for (;;) {
    runs.push_back(directions);
    total += result.samples_per_receiver;
    if (result.estimated_error <= max_error) {
      result.runs = std::move(runs);
      result.samples_per_receiver = total;
      result.pixel_directions.assign(static_cast<std::size_t>(result.width) * result.height, directions);
      return result;
    }
    // The need, as the estimate falls (K^-p), 5 % more; beyond kMaxAutoDirections refused.
    double order = 1.0;
    if (earlier > 0 && earlier_estimate > result.estimated_error && result.estimated_error > 0.0)
      order = std::clamp(std::log(earlier_estimate / result.estimated_error) / std::log(double(directions) / earlier),
                         0.5, 3.0);
    const double wanted = std::max<double>(
        directions + 8, directions * std::pow(result.estimated_error / max_error, 1.0 / order) * 1.05);
    // Refused only where the prediction is near enough to trust (within the step a run may take;
    // from the first run's order alone, or from far off, the runs step toward it instead), where
    // even a fall as K^-3 (the fastest order taken) would need more, or where the last run already
    // took the most directions.
    const double fastest = directions * std::pow(result.estimated_error / max_error, 1.0 / 3.0);  // as K^-3
    if (earlier > 0 && wanted > kMaxAutoDirections &&
        (wanted <= kHorizonMostStep * directions || directions >= kMaxAutoDirections ||
         fastest > kMaxAutoDirections)) {
      // In degrees, as the command line takes it.
      std::ostringstream message;
      message << "a maximum mean horizon angle error of " << max_error * 180.0 / M_PI << " degrees needs about "
              << static_cast<long long>(std::min(wanted, 1e9)) << " directions (the estimate at K = " << directions
              << " is " << result.estimated_error * 180.0 / M_PI << " degrees), beyond the " << kMaxAutoDirections
              << " a run may choose: ask for a larger error, or give K";
      throw InvalidArgument(message.str());
    }
    // After the first run the second (whose work is a few per cent of what follows) measures the
    // order; the third goes at most kHorizonThirdStep times as far and later runs kHorizonMostStep
    // times, where the order is measured again (it rises with K on smooth fields, and the estimate's
    // fall from 8 to 16 predicts badly far off: from 16 straight to 64, a need of 72 .. 104 then took
    // 128, where 16, 32 and a run near the need cost less: bench/report/error_target.md).
    const double most_step = earlier == kHorizonFirstDirections ? kHorizonThirdStep : kHorizonMostStep;
    const int reach =
        earlier == 0 ? kHorizonSecondDirections
                     : static_cast<int>(
                           std::ceil(std::min({wanted, most_step * directions, double(kMaxAutoDirections)})));
    const int fresh = earlier == 0 ? kHorizonSecondDirections : cheapestDirections(reach, work);
    // Or the last run extended to the least multiple of its K that reaches as far: only the
    // directions it adds are cast (bench/report/error_target.md, horizon angles).
    const int extended = (reach + directions - 1) / directions * directions;
    // (to the same K the extension costs less, whatever the work)
    const bool extend = extend_runs && extended > directions && extended <= kMaxAutoDirections &&
                        (extended == fresh || work(extended) - work(directions) <= work(fresh));
    earlier = directions;
    earlier_estimate = result.estimated_error;
    directions = extend ? extended : fresh;
    if (extend) {
      result = run(directions, &result);
    } else {
      result = HorizonResult();  // (its planes freed before the fresh run's: one run's planes at a time)
      result = run(directions, nullptr);
    }
  }
}

namespace {

// Puts `part`, whose direction k is `into`'s direction indices[k], in its places: its azimuths,
// angle and distance planes.
void placeHorizonRun(HorizonResult& into, const HorizonResult& part, const std::vector<int>& indices) {
  const std::size_t plane = static_cast<std::size_t>(into.width) * into.height;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    const std::size_t to = static_cast<std::size_t>(indices[k]);
    into.azimuths[to] = part.azimuths[k];
    if (!part.angles.empty())
      std::copy_n(part.angles.begin() + k * plane, plane, into.angles.begin() + to * plane);
    if (!part.distances.empty())
      std::copy_n(part.distances.begin() + k * plane, plane, into.distances.begin() + to * plane);
  }
}

}  // namespace

HorizonResult extendHorizonRun(HorizonResult from, int directions,
                               const std::function<HorizonResult(const std::vector<int>& indices)>& run) {
  const int K = from.directions, m = K > 0 ? directions / K : 0;
  if (m < 2 || directions % K != 0)
    throw std::logic_error("extendHorizonRun: " + std::to_string(directions) + " directions are no multiple of " +
                           std::to_string(K));
  const std::size_t plane = static_cast<std::size_t>(from.width) * from.height;
  std::vector<float> angles = std::move(from.angles), distances = std::move(from.distances);
  HorizonResult out = from;  // (the other fields a run sets)
  from.angles = std::move(angles), from.distances = std::move(distances);
  out.directions = directions;
  out.azimuths.assign(std::size_t(directions), 0.0);
  if (!from.angles.empty()) out.angles.assign(plane * directions, 0.0f);
  if (!from.distances.empty()) out.distances.assign(plane * directions, 0.0f);
  std::vector<int> own, between;
  for (int i = 0; i < directions; ++i) (i % m == 0 ? own : between).push_back(i);
  placeHorizonRun(out, from, own);
  from = HorizonResult();
  const HorizonResult part = run(between);
  if (part.directions != static_cast<int>(between.size()) || part.width != out.width || part.height != out.height)
    throw std::logic_error("extendHorizonRun: the run did not cast the directions asked for");
  placeHorizonRun(out, part, between);
  out.samples_per_receiver = part.samples_per_receiver;
  out.error_estimate.clear();
  out.estimated_error = 0.0;
  return out;
}

}  // namespace hfvis::detail
