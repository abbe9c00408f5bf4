// bench/error_target.cpp: see error_target.hpp.
#include "error_target.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>

#include "core/horizon_angle_error.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis_testing/intervisibility_reference.hpp"

namespace hfvis::bench {
namespace {

// The 99th percentile of |a - b| over the pixels with data, as max_error measures its estimate.
double p99Difference(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<float> d(a.size());
  for (std::size_t p = 0; p < a.size(); ++p) d[p] = std::abs(a[p] - b[p]);  // NaN where either is
  return detail::estimatedError(d);                                         // the same percentile
}

double seconds(const std::function<void()>& run) {
  const auto t0 = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One number as `format` (printf) writes it.
std::string formatted(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The work of a run at K per receiver: the samples of one period summed over its directions
// (the sweep's cost is linear in them; load-free, unlike a time).
std::size_t samplesPerReceiver(const HeightField& field, int K, const HorizonOutputs& outputs) {
  HorizonOptions options;
  options.directions = K;
  std::size_t samples = 0;
  for (const auto& d : detail::horizonDirections(field, options, outputs))
    samples += detail::latticeSamples(d, options.samples_per_unit).size();
  return samples;
}

struct Output {
  const char* name;
  bool HorizonOutputs::*wanted;
  std::vector<float> HorizonResult::*plane;
};

const Output kOutputs[] = {
    {"sky-view factor", &HorizonOutputs::sky_view_factor, &HorizonResult::sky_view_factor},
    {"ambient occlusion", &HorizonOutputs::ambient_occlusion, &HorizonResult::ambient_occlusion}};

// The output at K = reference_directions: the azimuthal integral the runs' errors are measured
// against. `wanted` and `options` are left asking for that output at that K.
std::vector<float> referencePlane(const ComputeContext& context, const HeightField& field,
                                  const Output& output, int reference_directions, HorizonOutputs& wanted,
                                  HorizonOptions& options) {
  wanted = HorizonOutputs{};
  wanted.*output.wanted = true;
  options = HorizonOptions{};
  options.directions = reference_directions;
  return computeHorizons(context, field, options, wanted).*output.plane;
}

// The work of a tree run at K per receiver: its directions' samples per period summed (the
// tree's cost is linear in them); `halves`: the error estimate's directions (steps merged only
// within a parity).
std::size_t treeSamplesPerReceiver(const HeightField& field, int K, bool halves) {
  IntervisibilityOptions options;
  options.directions = K;
  std::size_t samples = 0;
  for (const auto& d : detail::treeDirections(field, options, true, halves)) samples += d.per_period;
  return samples;
}

std::string spread(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? std::string("not measured")
                   : formatted("median %.2f", median(v)) + formatted(", largest %.2f", v.back());
}

}  // namespace

void errorTargetReport(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                       const std::vector<double>& errors, int reference_directions, int reps, int tile) {
  const std::vector<int> ladder = directionLadder();
  for (const Output& output : kOutputs) {
    std::printf("\n### %s\n\n", output.name);
    std::printf(
        "| field | E | whole field: runs (K) | estimate | achieved p99 | met | tiles of %d: K (runs) | "
        "estimate | "
        "achieved p99 | met | cheapest fixed K | its p99 | time whole (s) | time tiles (s) | time fixed (s) "
        "| "
        "time ratio whole | time ratio tiles | work ratio whole | last run's | work ratio tiles |\n"
        "|---|---:|---:|---:|---:|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        "\n",
        tile);
    int met = 0, tiles_met = 0, rows = 0;
    std::vector<double> ratios, tile_ratios, works, last_works, tile_works;
    for (const ErrorTargetField& f : fields) {
      HorizonOutputs wanted;
      HorizonOptions options;
      const std::vector<float> reference =
          referencePlane(context, f.field, output, reference_directions, wanted, options);
      std::map<int, double> fixed_error;  // K -> achieved p99 of a fixed-K run
      const auto errorAt = [&](int K) {
        auto it = fixed_error.find(K);
        if (it != fixed_error.end()) return it->second;
        options.directions = K;
        return fixed_error[K] =
                   p99Difference(computeHorizons(context, f.field, options, wanted).*output.plane, reference);
      };
      for (double E : errors) {
        HorizonOptions whole, tiled;
        whole.max_error = tiled.max_error = E;
        whole.error_tile = 0;
        tiled.error_tile = tile;
        HorizonResult result, refined;
        try {
          result = computeHorizons(context, f.field, whole, wanted);
          refined = computeHorizons(context, f.field, tiled, wanted);
        } catch (const InvalidArgument& error) {
          std::printf("| %s | %g | refused: %s |||||||||||||||||\n", f.name.c_str(), E, error.what());
          continue;
        }
        const double achieved = p99Difference(result.*output.plane, reference);
        const double tiles_achieved = p99Difference(refined.*output.plane, reference);
        int cheapest = 0;
        for (int K : ladder)
          if (errorAt(K) <= E) {
            cheapest = K;
            break;
          }
        // Interleaved: the whole field's runs, the tiles' runs and the cheapest fixed K's, in turn
        // (none with reps = 0: the work ratios alone, free of the machine's load).
        std::vector<double> t_whole, t_tiles, t_fixed;
        HorizonOptions fixed;
        fixed.directions = cheapest ? cheapest : kMaxAutoDirections;
        for (int r = 0; r < reps; ++r) {
          t_whole.push_back(seconds([&] { computeHorizons(context, f.field, whole, wanted); }));
          t_tiles.push_back(seconds([&] { computeHorizons(context, f.field, tiled, wanted); }));
          t_fixed.push_back(seconds([&] { computeHorizons(context, f.field, fixed, wanted); }));
        }
        const auto time = [&](const std::vector<double>& t) {
          return reps ? formatted("%.3f", median(t)) : "-";
        };
        const double ratio = reps ? median(t_whole) / median(t_fixed) : 0.0;
        const double tile_ratio = reps ? median(t_tiles) / median(t_fixed) : 0.0;
        HorizonOutputs estimated = wanted;
        estimated.error_estimate = true;
        const double fixed_work = samplesPerReceiver(f.field, fixed.directions, wanted);
        std::string runs;
        for (int K : result.runs) runs += (runs.empty() ? "" : ", ") + std::to_string(K);
        const double work = result.samples_per_receiver / fixed_work;
        const double last_work = samplesPerReceiver(f.field, result.directions, estimated) / fixed_work;
        const double tile_work = refined.samples_per_receiver / fixed_work;
        const auto [least, most] =
            std::minmax_element(refined.pixel_directions.begin(), refined.pixel_directions.end());
        const std::string tile_runs = std::to_string(*least) + ".." + std::to_string(*most) + " (" +
                                      std::to_string(refined.runs.size()) + ")";
        ++rows;
        met += achieved <= E;
        tiles_met += tiles_achieved <= E;
        if (cheapest) {
          if (reps) ratios.push_back(ratio), tile_ratios.push_back(tile_ratio);
          works.push_back(work);
          last_works.push_back(last_work);
          tile_works.push_back(tile_work);
        }
        std::printf(
            "| %s | %g | %s | %.5f | %.5f | %s | %s | %.5f | %.5f | %s | %s | %.5f | %s | %s | %s | %s | %s "
            "| %.2f | "
            "%.2f | %.2f |\n",
            f.name.c_str(), E, runs.c_str(), result.estimated_error, achieved,
            achieved <= E ? "yes" : "**no**", tile_runs.c_str(), refined.estimated_error, tiles_achieved,
            tiles_achieved <= E ? "yes" : "**no**", cheapest ? std::to_string(cheapest).c_str() : "none",
            cheapest ? errorAt(cheapest) : 0.0, time(t_whole).c_str(), time(t_tiles).c_str(),
            time(t_fixed).c_str(), reps ? formatted("%.2f", ratio).c_str() : "-",
            reps ? formatted("%.2f", tile_ratio).c_str() : "-", work, last_work, tile_work);
        std::fflush(stdout);
      }
    }
    std::printf(
        "\n%s: achieved error at most E in %d of %d cases (%.0f %%) with the whole field at one K, in %d "
        "with "
        "tiles of %d; over the cheapest fixed K: the whole field's time %s, work %s, its last run's work "
        "alone "
        "%s; the tiles' time %s, work %s\n",
        output.name, met, rows, rows ? 100.0 * met / rows : 0.0, tiles_met, tile, spread(ratios).c_str(),
        spread(works).c_str(), spread(last_works).c_str(), spread(tile_ratios).c_str(),
        spread(tile_works).c_str());
  }
}

void viewcountTargetReport(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                           const std::vector<double>& errors, int reference_directions, int reps) {
  const std::vector<int> ladder = directionLadder();
  std::printf(
      "\n### visible count (intervisibility, relative to its mean)\n\n"
      "| field | E | runs (K) | estimate | achieved p99 | met | cheapest fixed K | its p99 | time chosen (s) "
      "| "
      "time fixed (s) | time ratio | work ratio | last run's work ratio |\n"
      "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n");
  IntervisibilityOutputs wanted;
  wanted.visible_count = true;  // (the area is not estimated)
  int met = 0, rows = 0;
  std::vector<double> ratios, works, last_works;
  for (const ErrorTargetField& f : fields) {
    IntervisibilityOptions options;
    options.directions = reference_directions;
    const IntervisibilityResult reference = computeIntervisibility(context, f.field, options, wanted);
    std::map<int, double> fixed_error;  // K -> achieved p99 of a fixed-K run
    const auto errorAt = [&](int K) {
      auto it = fixed_error.find(K);
      if (it != fixed_error.end()) return it->second;
      options.directions = K;
      return fixed_error[K] =
                 countErrorP99(computeIntervisibility(context, f.field, options, wanted), reference);
    };
    for (double E : errors) {
      IntervisibilityOptions chosen;
      chosen.max_error = E;
      IntervisibilityResult result;
      try {
        result = computeIntervisibility(context, f.field, chosen, wanted);
      } catch (const InvalidArgument& error) {
        std::printf("| %s | %g | refused: %s |||||||||\n", f.name.c_str(), E, error.what());
        continue;
      }
      const double achieved = countErrorP99(result, reference);
      int cheapest = 0;
      for (int K : ladder)
        if (errorAt(K) <= E) {
          cheapest = K;
          break;
        }
      std::vector<double> t_chosen, t_fixed;
      IntervisibilityOptions fixed;
      fixed.directions = cheapest ? cheapest : kMaxAutoDirections;
      for (int r = 0; r < reps; ++r) {
        t_chosen.push_back(seconds([&] { computeIntervisibility(context, f.field, chosen, wanted); }));
        t_fixed.push_back(seconds([&] { computeIntervisibility(context, f.field, fixed, wanted); }));
      }
      const auto time = [&](const std::vector<double>& t) {
        return reps ? formatted("%.3f", median(t)) : "-";
      };
      const double ratio = reps ? median(t_chosen) / median(t_fixed) : 0.0;
      const double fixed_work = treeSamplesPerReceiver(f.field, fixed.directions, false);
      double work = 0.0;
      std::string runs;
      for (int K : result.runs) {
        work += treeSamplesPerReceiver(f.field, K, true);
        runs += (runs.empty() ? "" : ", ") + std::to_string(K);
      }
      const double last_work = treeSamplesPerReceiver(f.field, result.directions, true) / fixed_work;
      ++rows;
      met += achieved <= E;
      if (cheapest) {
        if (reps) ratios.push_back(ratio);
        works.push_back(work / fixed_work);
        last_works.push_back(last_work);
      }
      std::printf("| %s | %g | %s | %.5f | %.5f | %s | %s | %.5f | %s | %s | %s | %.2f | %.2f |\n",
                  f.name.c_str(), E, runs.c_str(), result.estimated_error, achieved,
                  achieved <= E ? "yes" : "**no**", cheapest ? std::to_string(cheapest).c_str() : "none",
                  cheapest ? errorAt(cheapest) : 0.0, time(t_chosen).c_str(), time(t_fixed).c_str(),
                  reps ? formatted("%.2f", ratio).c_str() : "-", work / fixed_work, last_work);
      std::fflush(stdout);
    }
  }
  std::printf(
      "\nvisible count: achieved error at most E in %d of %d cases (%.0f %%); over the cheapest fixed "
      "K: time %s; work %s; the last run's work alone %s\n",
      met, rows, rows ? 100.0 * met / rows : 0.0, spread(ratios).c_str(), spread(works).c_str(),
      spread(last_works).c_str());
}

void errorCurve(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                int reference_directions, int max_directions) {
  for (const Output& output : kOutputs) {
    std::printf(
        "\n### %s: error and estimate against K\n\n| field | K | samples | achieved p99 | estimate | "
        "p99 of r(K/2) - r(K) | time (s) |\n|---|---:|---:|---:|---:|---:|---:|\n",
        output.name);
    for (const ErrorTargetField& f : fields) {
      HorizonOutputs wanted;
      HorizonOptions options;
      const std::vector<float> reference =
          referencePlane(context, f.field, output, reference_directions, wanted, options);
      wanted.error_estimate = true;
      std::map<int, std::vector<float>> results;
      for (int K : directionLadder()) {
        if (K > max_directions) break;
        options.directions = K;
        HorizonResult result;
        const double t = seconds([&] { result = computeHorizons(context, f.field, options, wanted); });
        const std::size_t samples = samplesPerReceiver(f.field, K, wanted);
        results[K] = result.*output.plane;
        const auto half = results.find(K / 2);
        std::printf("| %s | %d | %zu | %.6f | %.6f | %.6f | %.4f |\n", f.name.c_str(), K, samples,
                    p99Difference(results[K], reference), result.estimated_error,
                    half == results.end() || K % 2 ? -1.0 : p99Difference(half->second, results[K]), t);
        std::fflush(stdout);
      }
    }
  }
}

void nestedCurve(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                 int reference_directions, int max_directions) {
  std::printf(
      "\n| field | K | copies | samples nested | samples uniform | SVF p99 nested | SVF p99 uniform | "
      "AO p99 nested | AO p99 uniform |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  HorizonOutputs both;
  both.sky_view_factor = both.ambient_occlusion = true;
  constexpr int kBase = 8;  // copies of 8 directions: the deepest sets
  for (const ErrorTargetField& f : fields) {
    HorizonOptions options;
    options.directions = reference_directions;
    const HorizonResult reference = computeHorizons(context, f.field, options, both);
    for (int m : {1, 2, 3, 4, 5, 6, 7, 8, 10, 12, 14, 16, 20, 24, 28, 32, 40, 48, 56, 64, 96, 128, 192, 256}) {
      if (m * kBase > max_directions) break;
      const HorizonResult nested = detail::computeNestedSet(context, f.field, options, both, kBase, m, true);
      options.directions = m * kBase;
      const HorizonResult uniform = computeHorizons(context, f.field, options, both);
      std::printf("| %s | %d | %d | %.0f | %.0f | %.5f | %.5f | %.5f | %.5f |\n", f.name.c_str(),
                  options.directions, m, nested.samples_per_receiver, uniform.samples_per_receiver,
                  p99Difference(nested.sky_view_factor, reference.sky_view_factor),
                  p99Difference(uniform.sky_view_factor, reference.sky_view_factor),
                  p99Difference(nested.ambient_occlusion, reference.ambient_occlusion),
                  p99Difference(uniform.ambient_occlusion, reference.ambient_occlusion));
      std::fflush(stdout);
    }
  }
}

namespace {

constexpr double kDegrees = 180.0 / M_PI;

// The dense reference's azimuth tolerance: 0.02 degrees, so that its K directions stay apart (at
// the default 0.25 degrees, K = 2048's spacing of 0.18 degrees would merge neighbours into one
// step and the reference would share the run's own azimuths).
constexpr double kReferenceTolerance = 0.02 * M_PI / 180.0;

// The horizon planes of `field` at K (`tolerance` 0: the default azimuth tolerance).
HorizonResult horizonPlanes(const ComputeContext& context, const HeightField& field, int K, bool estimate,
                            double tolerance = 0.0) {
  HorizonOptions options;
  options.directions = K;
  if (tolerance > 0.0) options.azimuth_tolerance = tolerance;
  HorizonOutputs wanted;
  wanted.horizon_angles = true;
  wanted.error_estimate = estimate;
  return computeHorizons(context, field, options, wanted);
}

}  // namespace

void horizonTargetReport(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                         const std::vector<double>& errors, int reference_directions, int reps) {
  std::printf(
      "\n### horizon angles (mean error, degrees)\n\n"
      "| field | E (deg) | runs (K) | estimate | achieved mean | met | cheapest fixed K | its mean | "
      "time chosen (s) | time fixed (s) | time ratio | work ratio | last run's work ratio |\n"
      "|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n");
  HorizonOutputs wanted;
  wanted.horizon_angles = true;
  int met = 0, rows = 0;
  std::vector<double> ratios, works, last_works;
  for (const ErrorTargetField& f : fields) {
    const HorizonResult reference =
        horizonPlanes(context, f.field, reference_directions, false, kReferenceTolerance);
    std::map<int, double> fixed_error;  // K -> achieved mean error (degrees) of a fixed-K run
    std::map<int, double> fixed_work;   // K -> its samples per receiver
    const auto errorAt = [&](int K) {
      auto it = fixed_error.find(K);
      if (it != fixed_error.end()) return it->second;
      const HorizonResult r = horizonPlanes(context, f.field, K, false);
      fixed_work[K] = r.samples_per_receiver;
      return fixed_error[K] = kDegrees * detail::horizonAngleErrorAgainst(r, reference);
    };
    for (double E : errors) {
      HorizonOptions chosen;
      chosen.max_error = E / kDegrees;
      HorizonResult result;
      try {
        result = computeHorizons(context, f.field, chosen, wanted);
      } catch (const InvalidArgument& error) {
        std::printf("| %s | %g | refused: %s ||||||||||\n", f.name.c_str(), E, error.what());
        continue;
      }
      const double achieved = kDegrees * detail::horizonAngleErrorAgainst(result, reference);
      // The cheapest fixed K meeting E: the least multiple of 8 that meets it, by bisection (the
      // error falls with K), then of the multiples of 8 up to twice that the one of least work
      // (the sweep's work is not monotone in K), if it meets E too.
      int cheapest = 0;
      if (errorAt(kMaxAutoDirections) <= E) {
        int lo = 1, hi = kMaxAutoDirections / 8;  // (hi * 8 meets E)
        while (lo < hi) {
          const int mid = (lo + hi) / 2;
          if (errorAt(8 * mid) <= E) hi = mid; else lo = mid + 1;
        }
        cheapest = 8 * hi;
        double least = detail::horizonWork(f.field, HorizonOptions{}, wanted, cheapest);
        for (int K = cheapest + 8; K <= std::min(2 * 8 * hi, kMaxAutoDirections); K += 8) {
          const double w = detail::horizonWork(f.field, HorizonOptions{}, wanted, K);
          if (w < least && errorAt(K) <= E) least = w, cheapest = K;
        }
      }
      std::vector<double> t_chosen, t_fixed;
      const int fixed_k = cheapest ? cheapest : kMaxAutoDirections;
      for (int r = 0; r < reps; ++r) {
        t_chosen.push_back(seconds([&] { computeHorizons(context, f.field, chosen, wanted); }));
        t_fixed.push_back(seconds([&] { horizonPlanes(context, f.field, fixed_k, false); }));
      }
      const auto time = [&](const std::vector<double>& t) { return reps ? formatted("%.3f", median(t)) : "-"; };
      const double ratio = reps ? median(t_chosen) / median(t_fixed) : 0.0;
      errorAt(fixed_k);
      const double work = result.samples_per_receiver / fixed_work[fixed_k];
      errorAt(result.directions);
      const double last_work = fixed_work[result.directions] / fixed_work[fixed_k];
      std::string runs;
      for (int K : result.runs) runs += (runs.empty() ? "" : ", ") + std::to_string(K);
      ++rows;
      met += achieved <= E;
      if (cheapest) {
        if (reps) ratios.push_back(ratio);
        works.push_back(work);
        last_works.push_back(last_work);
      }
      std::printf("| %s | %g | %s | %.4f | %.4f | %s | %s | %.4f | %s | %s | %s | %.2f | %.2f |\n", f.name.c_str(),
                  E, runs.c_str(), kDegrees * result.estimated_error, achieved, achieved <= E ? "yes" : "**no**",
                  cheapest ? std::to_string(cheapest).c_str() : "none", cheapest ? errorAt(cheapest) : 0.0,
                  time(t_chosen).c_str(), time(t_fixed).c_str(), reps ? formatted("%.2f", ratio).c_str() : "-",
                  work, last_work);
      std::fflush(stdout);
    }
  }
  std::printf(
      "\nhorizon angles: achieved mean error at most E in %d of %d cases (%.0f %%); over the cheapest fixed "
      "K: time %s; work %s; the last run's work alone %s\n",
      met, rows, rows ? 100.0 * met / rows : 0.0, spread(ratios).c_str(), spread(works).c_str(),
      spread(last_works).c_str());
}

void horizonErrorCurve(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                       int reference_directions, int max_directions) {
  std::printf(
      "\n### horizon angles: mean error and estimate against K (degrees)\n\n| field | K | samples | achieved "
      "mean | estimate | achieved / estimate | skip-one | skip-two | order p | time (s) |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const ErrorTargetField& f : fields) {
    const HorizonResult reference =
        horizonPlanes(context, f.field, reference_directions, false, kReferenceTolerance);
    for (int K : directionLadder()) {
      if (K > max_directions) break;
      HorizonResult result;
      const double t = seconds([&] { result = horizonPlanes(context, f.field, K, true); });
      const detail::SkipErrors skips = detail::horizonSkipErrors(result);
      const double achieved = kDegrees * detail::horizonAngleErrorAgainst(result, reference);
      const double estimate = kDegrees * result.estimated_error;
      std::printf("| %s | %d | %.0f | %.4f | %.4f | %.2f | %.4f | %.4f | %.2f | %.4f |\n", f.name.c_str(), K,
                  result.samples_per_receiver, achieved, estimate, estimate > 0 ? achieved / estimate : 0.0,
                  kDegrees * detail::meanWithData(skips.skip_one), kDegrees * detail::meanWithData(skips.skip_two),
                  detail::horizonErrorOrder(skips), t);
      std::fflush(stdout);
    }
  }
}

}  // namespace hfvis::bench
