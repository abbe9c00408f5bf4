// bench/metrics.cpp: timings, errors against the ground truth, host SVF/AO formulas and
// hull-stack statistics.
#include "metrics.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "hfvis/errors.hpp"
#include "core/lattice_geometry.hpp"
#include "core/sweep_geometry.hpp"

namespace hfvis::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegrees = 180.0 / kPi;

// Accumulates absolute and signed differences; percentiles need every value.
struct Accumulator {
  std::vector<double> abs_values;
  double signed_sum = 0.0;
  std::size_t nan = 0;
  void add(double difference) {
    if (std::isnan(difference)) {
      ++nan;
      return;
    }
    abs_values.push_back(std::abs(difference));
    signed_sum += difference;
  }
  double mean() const {
    double s = 0.0;
    for (double v : abs_values) s += v;
    return abs_values.empty() ? 0.0 : s / abs_values.size();
  }
  double max() const {
    return abs_values.empty() ? 0.0 : *std::max_element(abs_values.begin(), abs_values.end());
  }
  double percentile(double p) {
    if (abs_values.empty()) return 0.0;
    const std::size_t at = std::min(abs_values.size() - 1, static_cast<std::size_t>(p * abs_values.size()));
    std::nth_element(abs_values.begin(), abs_values.begin() + at, abs_values.end());
    return abs_values[at];
  }
};

// Errors of `angles` against `expected(receiver, k)` over the truth's receivers.
template <typename Expected>
ErrorStats compare(const HeightField& field, const GroundTruth& truth, const std::vector<float>& angles,
                   int directions, Expected expected) {
  if (directions < 1 || truth.directions % directions != 0)
    throw InvalidArgument("error evaluation needs K dividing the ground truth's " +
                          std::to_string(truth.directions) + " directions (got " +
                          std::to_string(directions) + ")");
  const std::size_t plane = field.pixelCount();
  if (angles.size() != plane * directions)
    throw InvalidArgument("horizon planes missing for the error evaluation");
  Accumulator angle, inner, svf, ao;
  std::vector<double> got(directions), want(directions);
  // At least two pixels from every edge: away from where rays leave the field at once.
  auto interior = [&](std::size_t pixel) {
    const int c = static_cast<int>(pixel % field.width), r = static_cast<int>(pixel / field.width);
    return c >= 2 && r >= 2 && c < field.width - 2 && r < field.height - 2;
  };
  for (std::size_t n = 0; n < truth.receivers.size(); ++n) {
    const std::size_t pixel = truth.receivers[n];
    for (int k = 0; k < directions; ++k) {
      got[k] = angles[k * plane + pixel];
      want[k] = expected(n, k);
      angle.add((got[k] - want[k]) * kDegrees);
      if (interior(pixel)) inner.add((got[k] - want[k]) * kDegrees);
    }
    const Normal normal =
        surfaceNormal(field, static_cast<int>(pixel % field.width), static_cast<int>(pixel / field.width));
    svf.add(skyViewFactor(got) - skyViewFactor(want));
    ao.add(ambientOcclusion(got, normal) - ambientOcclusion(want, normal));
  }
  ErrorStats s;
  s.samples = angle.abs_values.size();
  s.nan_samples = angle.nan;
  s.mean_deg = angle.mean();
  s.p99_deg = angle.percentile(0.99);
  s.max_deg = angle.max();
  s.bias_deg = s.samples ? angle.signed_sum / s.samples : 0.0;
  s.interior_samples = inner.abs_values.size();
  s.interior_mean_deg = inner.mean();
  s.interior_p99_deg = inner.percentile(0.99);
  s.interior_max_deg = inner.max();
  s.svf_mean = svf.mean(), s.svf_max = svf.max();
  s.ao_mean = ao.mean(), s.ao_max = ao.max();
  return s;
}

}  // namespace

double Timing::min() const {
  return seconds.empty() ? 0.0 : *std::min_element(seconds.begin(), seconds.end());
}

double Timing::median() const {
  if (seconds.empty()) return 0.0;
  std::vector<double> sorted = seconds;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t n = sorted.size();
  return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

double Timing::cpuMin() const {
  return cpu_seconds.empty() ? 0.0 : *std::min_element(cpu_seconds.begin(), cpu_seconds.end());
}

double processCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return t.tv_sec + t.tv_usec * 1e-6; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

Timing timeRepeated(const std::function<void()>& run, const TimingPolicy& policy) {
  Timing timing;
  double spent = 0.0;
  while (static_cast<int>(timing.seconds.size()) < policy.max_reps &&
         (static_cast<int>(timing.seconds.size()) < policy.min_reps || spent < policy.budget_seconds)) {
    const double cpu = processCpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    run();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    timing.cpu_seconds.push_back(processCpuSeconds() - cpu);
    timing.seconds.push_back(s);
    spent += s;
  }
  return timing;
}

Normal surfaceNormal(const HeightField& field, int c, int r) {
  // The sum of the normals of the (up to) four quads around the pixel, as surface_normal
  // in kernels/horizon.cl (quads touching nodata or the border left out), with heights times
  // z_scale and lengths in ground units.
  auto at = [&](int col, int row) {
    return static_cast<double>(field.heights[static_cast<std::size_t>(row) * field.width + col]) *
           field.z_scale;
  };
  const double h = at(c, r);
  double nx = 0.0, ny = 0.0, nz = 0.0;
  for (int sy = -1; sy <= 1; sy += 2) {
    for (int sx = -1; sx <= 1; sx += 2) {
      const int cx = c + sx, ry = r + sy;
      if (cx < 0 || cx >= field.width || ry < 0 || ry >= field.height) continue;
      if (!std::isfinite(at(cx, r)) || !std::isfinite(at(c, ry))) continue;  // quads touching nodata
      nx -= (at(cx, r) - h) / (sx * field.cell_size_x);
      ny -= (at(c, ry) - h) / (sy * field.cell_size_y);
      nz += 1.0;
    }
  }
  if (!(nz > 0.0)) return {};
  const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
  return {nx / len, ny / len, nz / len};
}

double skyViewFactor(const std::vector<double>& elevations) {
  double sum = 0.0;
  for (double e : elevations) sum += std::sin(std::max(0.0, e));
  return 1.0 - sum / elevations.size();
}

double ambientOcclusion(const std::vector<double>& elevations, const Normal& n,
                        const std::vector<double>& azimuths) {
  // Eq. 5 of Timonen & Westerholm 2010 per azimuthal swath, as ambient_term in the kernel.
  const int k_count = static_cast<int>(elevations.size());
  if (!azimuths.empty() && azimuths.size() != elevations.size())
    throw InvalidArgument("ambientOcclusion: one azimuth per elevation");
  double sum = 0.0;
  for (int k = 0; k < k_count; ++k) {
    const double phi = azimuths.empty() ? 2.0 * kPi * k / k_count : azimuths[k];
    const double cos_az = std::abs(std::cos(phi)) < 1e-12 ? 0.0 : std::cos(phi);
    const double sin_az = std::abs(std::sin(phi)) < 1e-12 ? 0.0 : std::sin(phi);
    const double toward = n.x * cos_az + n.y * sin_az;
    const double zenith = std::min(0.5 * kPi - elevations[k], 0.5 * kPi + std::atan(toward / n.z));
    const double s = std::sin(zenith);
    sum += n.z / k_count * s * s +
           std::sin(kPi / k_count) / kPi * (zenith - 0.5 * std::sin(2.0 * zenith)) * toward;
  }
  return sum;
}

ErrorStats horizonErrors(const HeightField& field, const GroundTruth& truth, const std::vector<float>& angles,
                         int directions) {
  const int every = truth.directions / std::max(directions, 1);
  return compare(field, truth, angles, directions,
                 [&](std::size_t n, int k) { return truth.angle(n, k * every); });
}

ErrorStats horizonDifference(const HeightField& field, const GroundTruth& truth,
                             const std::vector<float>& angles, const std::vector<float>& reference,
                             int directions) {
  const std::size_t plane = field.pixelCount();
  return compare(field, truth, angles, directions, [&](std::size_t n, int k) {
    return static_cast<double>(reference[k * plane + truth.receivers[n]]);
  });
}

SvfErrorStats svfErrors(const HeightField& field, const GroundTruth& truth, const std::vector<float>& svf,
                        int directions) {
  if (directions < 1 || truth.directions % directions != 0)
    throw InvalidArgument("SVF error evaluation needs K dividing the ground truth's " +
                          std::to_string(truth.directions) + " directions (got " +
                          std::to_string(directions) + ")");
  if (svf.size() != field.pixelCount())
    throw InvalidArgument("sky-view factor plane missing for the error evaluation");
  const int every = truth.directions / directions;
  Accumulator acc;
  std::vector<double> exact(directions);
  for (std::size_t n = 0; n < truth.receivers.size(); ++n) {
    for (int k = 0; k < directions; ++k) exact[k] = truth.angle(n, k * every);
    acc.add(static_cast<double>(svf[truth.receivers[n]]) - skyViewFactor(exact));
  }
  SvfErrorStats s;
  s.receivers = acc.abs_values.size();
  s.nan_receivers = acc.nan;
  s.mean_abs = acc.mean();
  s.max_abs = acc.max();
  s.bias = s.receivers ? acc.signed_sum / s.receivers : 0.0;
  return s;
}

PlaneDifference planeDifference(const std::vector<float>& a, const std::vector<float>& b) {
  Accumulator acc;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    if (!std::isnan(a[i]) || !std::isnan(b[i])) acc.add(static_cast<double>(a[i]) - b[i]);
  return {acc.mean(), acc.max()};
}

StackStats hullStackStatistics(const HeightField& field, int directions) {
  const std::vector<float> heights = detail::prepareHeights(field).heights;
  const int w = field.width, h = field.height;
  SweepOptions options;
  options.directions = directions;
  StackStats stats;
  double pops = 0.0, depth = 0.0;
  std::vector<std::pair<float, float>> stack;  // (height, position along the line)
  for (const detail::LatticeDirection& d : detail::latticeDirections(field, options, false, 0.0)) {
    const std::vector<detail::LatticeSample> samples = detail::latticeSamples(d, 1.0);
    auto push = [&](float height, float here) {
      ++stats.samples;
      depth += static_cast<double>(stack.size());
      // Algorithm 1 as horizon_lattice runs it: pop while the entry below the top casts at least as
      // steep a slope on the sample as the top.
      while (stack.size() > 1) {
        const auto top = stack.back(), below = stack[stack.size() - 2];
        if ((below.first - height) * (here - top.second) >= (top.first - height) * (here - below.second)) {
          stack.pop_back();
          pops += 1.0;
        } else {
          break;
        }
      }
      stack.emplace_back(height, here);
      stats.max_depth = std::max(stats.max_depth, static_cast<int>(stack.size()));
    };
    for (const detail::LatticeLine& line : detail::latticeLines(d, w, h)) {
      stack.clear();
      int c = line.col, r = line.row;
      for (int i = 0; i < line.receivers; ++i, c -= d.a, r -= d.b) {
        const float base = static_cast<float>(i * d.period);
        for (std::size_t q = 0; q + 1 < samples.size(); ++q) {
          const detail::LatticeSample& s = samples[q];
          const int x0 = c + s.ox, y0 = r + s.oy;
          if (x0 < 0 || x0 + s.ex > w - 1 || y0 < 0 || y0 + s.ey > h - 1) continue;
          const std::size_t at = static_cast<std::size_t>(y0) * w + x0;
          const float height = detail::cornerBilinear(heights[at], heights[at + s.ex], heights[at + s.ey * w],
                                                      heights[at + s.ey * w + s.ex], s.w10, s.w01, s.w11);
          push(height, base - s.tau);
        }
        push(heights[static_cast<std::size_t>(r) * w + c], base);
        ++stats.receivers;
      }
    }
  }
  if (stats.samples) {
    stats.pops_per_sample = pops / stats.samples;
    stats.mean_depth = depth / stats.samples;
  }
  return stats;
}

}  // namespace hfvis::bench
