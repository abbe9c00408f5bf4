// bench/error_target.cpp: see error_target.hpp.
#include "error_target.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>

#include "core/horizon_common.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"

namespace hfvis::bench {
namespace {

// The 99th percentile of |a - b| over the pixels with data, as max_error measures its estimate.
double p99Difference(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<float> d(a.size());
  for (std::size_t p = 0; p < a.size(); ++p) d[p] = std::abs(a[p] - b[p]);  // NaN where either is
  return detail::estimatedError(d);                                        // the same percentile
}

double seconds(const std::function<void()>& run) {
  const auto t0 = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The fixed K the search tries, cheapest first: multiples of 8, about 12-25 % apart.
std::vector<int> fixedLadder() {
  std::vector<int> ladder;
  for (int step = 8, k = 8; k <= kMaxAutoDirections; k += step) {
    ladder.push_back(k);
    if (k >= 8 * step) step *= 2;
  }
  return ladder;
}

struct Output {
  const char* name;
  bool HorizonOutputs::*wanted;
  std::vector<float> HorizonResult::*plane;
};

}  // namespace

void errorTargetReport(const ComputeContext& context, const std::vector<ErrorTargetField>& fields,
                       const std::vector<double>& errors, int reference_directions, int reps) {
  const Output outputs[] = {
      {"sky-view factor", &HorizonOutputs::sky_view_factor, &HorizonResult::sky_view_factor},
      {"ambient occlusion", &HorizonOutputs::ambient_occlusion, &HorizonResult::ambient_occlusion}};
  const std::vector<int> ladder = fixedLadder();
  for (const Output& output : outputs) {
    std::printf("\n### %s\n\n", output.name);
    std::printf(
        "| field | E | K chosen | estimate | achieved p99 | met | cheapest fixed K | its p99 | time chosen "
        "(s) | "
        "time fixed (s) | ratio |\n|---|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|\n");
    int met = 0, rows = 0;
    std::vector<double> ratios;
    for (const ErrorTargetField& f : fields) {
      HorizonOutputs wanted;
      wanted.*output.wanted = true;
      HorizonOptions options;
      options.directions = reference_directions;
      const std::vector<float> reference = computeHorizons(context, f.field, options, wanted).*output.plane;
      std::map<int, double> fixed_error;  // K -> achieved p99 of a fixed-K run
      const auto errorAt = [&](int K) {
        auto it = fixed_error.find(K);
        if (it != fixed_error.end()) return it->second;
        options.directions = K;
        return fixed_error[K] =
                   p99Difference(computeHorizons(context, f.field, options, wanted).*output.plane, reference);
      };
      for (double E : errors) {
        HorizonOptions chosen;
        chosen.max_error = E;
        HorizonResult result;
        try {
          result = computeHorizons(context, f.field, chosen, wanted);
        } catch (const InvalidArgument& error) {
          std::printf("| %s | %g | refused: %s |||||||||\n", f.name.c_str(), E, error.what());
          continue;
        }
        const double achieved = p99Difference(result.*output.plane, reference);
        int cheapest = 0;
        for (int K : ladder)
          if (errorAt(K) <= E) {
            cheapest = K;
            break;
          }
        // Interleaved: the chosen run (all its runs) and the cheapest fixed K's, alternately.
        std::vector<double> t_chosen, t_fixed;
        HorizonOptions fixed;
        fixed.directions = cheapest ? cheapest : kMaxAutoDirections;
        for (int r = 0; r < reps; ++r) {
          t_chosen.push_back(seconds([&] { computeHorizons(context, f.field, chosen, wanted); }));
          t_fixed.push_back(seconds([&] { computeHorizons(context, f.field, fixed, wanted); }));
        }
        const double ratio = median(t_chosen) / median(t_fixed);
        ++rows;
        met += achieved <= E;
        if (cheapest) ratios.push_back(ratio);
        std::printf("| %s | %g | %d | %.5f | %.5f | %s | %s | %.5f | %.3f | %.3f | %.2f |\n", f.name.c_str(),
                    E, result.directions, result.estimated_error, achieved, achieved <= E ? "yes" : "**no**",
                    cheapest ? std::to_string(cheapest).c_str() : "none", cheapest ? errorAt(cheapest) : 0.0,
                    median(t_chosen), median(t_fixed), ratio);
        std::fflush(stdout);
      }
    }
    std::sort(ratios.begin(), ratios.end());
    std::printf(
        "\n%s: achieved error at most E in %d of %d cases (%.0f %%); time over the cheapest fixed K: "
        "median %.2f, largest %.2f\n",
        output.name, met, rows, rows ? 100.0 * met / rows : 0.0, ratios.empty() ? 0.0 : median(ratios),
        ratios.empty() ? 0.0 : ratios.back());
  }
}

}  // namespace hfvis::bench
