// bench/visibility_suite.cpp: the intervisibility part of the benchmark (issue 4), written to
// visibility.csv. Sections (the `section` column):
//   vis_time   the convex hull tree against the naive visibility march at the same K, visible
//              counts, on the four synthetic fields and the DEM (seed 000, Table 3), for each
//              tree tuning (Algorithm 1 as written, deferred writes, deferred writes + safe zone)
//   vis_stats  m_a, t_a per point and direction for Algorithm 1 and for the default tuning,
//              against seed 000 Table 2, with the share of walks the safe zone skipped
//   vis_zone   the safe zone's span (steps) against time, iterations and skips
//   vis_scale  iterations per line against line length n for fractal detail and random
//              extent (seed 000, Figure 8; the report fits the exponents for n >= 512)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <random>

#include "environment.hpp"
#include "hfvis/intervisibility.hpp"
#include "metrics.hpp"
#include "suite_support.hpp"

namespace hfvis::bench {
namespace {

namespace fs = std::filesystem;

struct VisibilityConfig {
  std::vector<std::string> contents = {"fractal", "bricks", "sine", "blocks", "dem"};
  int n = 1024;       // synthetic fields are n x n; the DEM is used whole (403 x 344)
  int time_k = 16;    // K of the timed runs (tree and naive)
  int stats_k = 64;   // K of the statistics
  std::vector<int> zone_steps = {1, 4, 16, 64, 256};
  std::vector<std::string> zone_contents = {"fractal", "dem"};
  std::vector<int> scale_ns;  // line lengths of the scaling study
  int scale_lines = 64;       // lines per length
  int rounds = 3;             // vis_time: timed runs of each tree tuning ...
  int naive_rounds = 2;       // ... and of the naive march (interleaved)
  TimingPolicy policy;        // vis_zone
};

VisibilityConfig visibilityConfigFor(const std::string& mode) {
  VisibilityConfig c;
  if (mode == "full") {
    c.policy = {2, 3, 2.0};
    for (int n = 64; n <= 16384; n *= 2) c.scale_ns.push_back(n);
  } else if (mode == "quick") {
    c.n = 256;
    c.time_k = 8;
    c.stats_k = 16;
    c.zone_steps = {1, 16, 256};
    c.rounds = c.naive_rounds = 2;
    c.policy = {2, 2, 0.3};
    for (int n = 64; n <= 2048; n *= 2) c.scale_ns.push_back(n);
  } else {  // tiny: the smoke test
    c.contents = {"sine", "fractal", "dem"};
    c.zone_contents = {"fractal"};
    c.n = 40;
    c.time_k = 4;
    c.stats_k = 4;
    c.zone_steps = {1, 16};
    c.scale_ns = {16, 32, 64};
    c.scale_lines = 4;
    c.rounds = c.naive_rounds = 1;
    c.policy = {1, 1, 0.0};
  }
  return c;
}

// clang-format off
const std::vector<std::string> kVisibilityColumns = {
    "section", "content", "width", "height", "method", "tuning", "zone_steps", "K", "reps", "t_min_s",
    "t_median_s", "t_all_s", "cpu_min_s", "load_1min", "pixel_dirs", "core_ns_per_pd", "cpu_ns_per_pd",
    "receivers", "lines", "m_a", "t_a", "visible_a", "naive_a", "skip_fraction", "lines_over_bound", "n",
    "t_per_line", "m_per_line", "note"};
// clang-format on

struct NamedTuning {
  std::string name;
  HullTreeTuning tuning;
};

HullTreeTuning zoneTuning(int steps) {
  HullTreeTuning t = *hullTreeTuningNamed("zone");
  t.safe_zone_steps = steps;
  return t;
}

// Algorithm 1 as written, each optimisation added in turn: deferred writes, the replacement
// check (the library's default), the safe zone.
std::vector<NamedTuning> tunings() {
  std::vector<NamedTuning> all;
  for (const char* name : {"plain", "deferred", "default", "zone"}) all.push_back({name, *hullTreeTuningNamed(name)});
  return all;
}

class VisibilitySuite {
 public:
  VisibilitySuite(const ComputeContext& context, const SuiteOptions& options, CsvWriter& out)
      : context_(context),
        options_(options),
        config_(visibilityConfigFor(options.mode)),
        out_(out),
        cores_(std::max(1, context.device().compute_units)) {}

  void run() {
    for (const auto& name : config_.contents) {
      const Content content = loadContent(options_, name, config_.n);
      timeContent(content);
      statistics(content);
      if (std::count(config_.zone_contents.begin(), config_.zone_contents.end(), name)) zone(content);
    }
    scaling();
  }

 private:
  // One library call, timed as the horizon suite times its methods.
  Timing timed(const HeightField& field, const IntervisibilityOptions& options,
               const IntervisibilityOutputs& outputs) {
    return timeWithWarmUp([&] { computeIntervisibility(context_, crop(field, 64, 64), options, outputs); },
                          [&] { computeIntervisibility(context_, field, options, outputs); }, config_.policy);
  }

  Row timingRow(const std::string& section, const Content& content, const std::string& method,
                const std::string& tuning, int zone_steps, int k, const Timing& t) const {
    Row row;
    row["section"] = section;
    row["content"] = content.name;
    row["width"] = std::to_string(content.field.width);
    row["height"] = std::to_string(content.field.height);
    row["method"] = method;
    row["tuning"] = tuning;
    if (zone_steps > 0) row["zone_steps"] = std::to_string(zone_steps);
    row["K"] = std::to_string(k);
    row["reps"] = std::to_string(t.seconds.size());
    row["t_min_s"] = num(t.min());
    row["t_median_s"] = num(t.median());
    std::string all;
    for (double s : t.seconds) all += (all.empty() ? "" : ";") + num(s);
    row["t_all_s"] = all;
    row["cpu_min_s"] = num(t.cpuMin());
    row["load_1min"] = loadAverage().substr(0, loadAverage().find(' '));
    const double pd = static_cast<double>(content.field.pixelCount()) * k;
    row["pixel_dirs"] = num(pd);
    row["core_ns_per_pd"] = num(t.min() * cores_ / pd * 1e9);
    row["cpu_ns_per_pd"] = num(t.cpuMin() / pd * 1e9);
    return row;
  }

  static void addStatistics(Row& row, const IntervisibilityStatistics& s) {
    row["receivers"] = std::to_string(s.receivers);
    row["lines"] = std::to_string(s.lines);
    row["m_a"] = num(s.meanHorizons());
    row["t_a"] = num(s.meanIterations());
    row["visible_a"] = num(s.meanVisible());
    row["naive_a"] = num(s.meanNaiveIterations());
    row["skip_fraction"] = num(s.receivers ? double(s.safe_zone_skips) / s.receivers : 0.0);
    row["lines_over_bound"] = std::to_string(s.lines_over_bound);
  }

  IntervisibilityStatistics statisticsOf(const HeightField& field, int k, const HullTreeTuning& tuning) {
    IntervisibilityOptions options;
    options.directions = k;
    options.tree = tuning;
    IntervisibilityOutputs outputs;
    outputs.statistics = true;
    return computeIntervisibility(context_, field, options, outputs).statistics;
  }

  // Visible counts by every tree tuning and by the naive march, same K. The runs are
  // interleaved (one of each method per round) so that a slow spell of the machine does
  // not land on one method only; the naive march, the slowest, runs naive_rounds of them.
  void timeContent(const Content& content) {
    IntervisibilityOutputs outputs;
    outputs.visible_count = true;
    std::vector<IntervisibilityOptions> methods;
    for (const NamedTuning& t : tunings()) {
      methods.emplace_back();
      methods.back().directions = config_.time_k;
      methods.back().tree = t.tuning;
    }
    methods.emplace_back();
    methods.back().directions = config_.time_k;
    methods.back().method = IntervisibilityMethod::Naive;
    for (const auto& options : methods)  // builds and caches each program
      computeIntervisibility(context_, crop(content.field, 64, 64), options, outputs);
    std::vector<Timing> timings(methods.size());
    for (int round = 0; round < config_.rounds; ++round) {
      for (std::size_t i = 0; i < methods.size(); ++i) {
        const bool naive = methods[i].method == IntervisibilityMethod::Naive;
        if (naive && round >= config_.naive_rounds) continue;
        const Timing one =
            timeRepeated([&] { computeIntervisibility(context_, content.field, methods[i], outputs); }, {1, 1, 0.0});
        timings[i].seconds.push_back(one.seconds[0]);
        timings[i].cpu_seconds.push_back(one.cpu_seconds[0]);
      }
    }
    for (std::size_t i = 0; i < methods.size(); ++i) {
      const bool naive = methods[i].method == IntervisibilityMethod::Naive;
      const HullTreeTuning& tuning = methods[i].tree;
      const std::string name = naive ? "" : tunings()[i].name;
      Row row = timingRow("vis_time", content, naive ? "naive" : "tree", name,
                          !naive && tuning.safe_zone ? tuning.safe_zone_steps : 0, config_.time_k, timings[i]);
      if (!naive) addStatistics(row, statisticsOf(content.field, config_.time_k, tuning));
      out_.write(row);
      say("[vis_time] %s %s %s K=%d: min %.3f s (%zu runs)", content.label.c_str(), naive ? "naive" : "tree",
          name.c_str(), config_.time_k, timings[i].min(), timings[i].seconds.size());
    }
  }

  void statistics(const Content& content) {
    for (const NamedTuning& t : tunings()) {
      if (t.name == "deferred") continue;  // the same iterations as plain
      Row row;
      row["section"] = "vis_stats";
      row["content"] = content.name;
      row["width"] = std::to_string(content.field.width);
      row["height"] = std::to_string(content.field.height);
      row["method"] = "tree";
      row["tuning"] = t.name;
      row["K"] = std::to_string(config_.stats_k);
      const auto s = statisticsOf(content.field, config_.stats_k, t.tuning);
      addStatistics(row, s);
      out_.write(row);
      say("[vis_stats] %s (%s) K=%d: m_a %.2f, t_a %.2f, skipped %.1f %%", content.label.c_str(),
          t.name.c_str(), config_.stats_k, s.meanHorizons(), s.meanIterations(),
          s.receivers ? 100.0 * s.safe_zone_skips / s.receivers : 0.0);
    }
  }

  void zone(const Content& content) {
    IntervisibilityOutputs outputs;
    outputs.visible_count = true;
    for (int steps : config_.zone_steps) {
      IntervisibilityOptions options;
      options.directions = config_.time_k;
      options.tree = zoneTuning(steps);
      const Timing timing = timed(content.field, options, outputs);
      Row row = timingRow("vis_zone", content, "tree", "zone", steps, config_.time_k, timing);
      addStatistics(row, statisticsOf(content.field, config_.time_k, options.tree));
      out_.write(row);
      say("[vis_zone] %s zone %d steps: min %.3f s", content.label.c_str(), steps, timing.min());
    }
  }

  // Figure 8: lines of n samples, one per row of an n x lines field swept along the rows.
  // Fractal detail: one midpoint-displacement profile per row at the longest n, each level's
  // offsets uniform with half the previous range; length n takes every (n_max / n)-th point,
  // so doubling n adds detail between the existing points. Random extent: independent
  // uniform heights in [0, 1), fresh for every n.
  void scaling() {
    const int n_max = config_.scale_ns.back();
    std::mt19937 rng(2013);
    std::vector<std::vector<float>> profiles(config_.scale_lines, std::vector<float>(n_max + 1));
    for (auto& p : profiles) {
      std::uniform_real_distribution<float> end(0.0f, 1.0f);
      p[0] = end(rng);
      p[n_max] = end(rng);
      float range = 0.5f;
      for (int half = n_max / 2; half >= 1; half /= 2, range *= 0.5f) {
        std::uniform_real_distribution<float> offset(-range, range);
        for (int i = half; i < n_max; i += 2 * half) p[i] = 0.5f * (p[i - half] + p[i + half]) + offset(rng);
      }
    }
    for (const std::string kind : {"fractal_detail", "random_extent"}) {
      for (int n : config_.scale_ns) {
        HeightField field;
        field.width = n;
        field.height = config_.scale_lines;
        field.heights.resize(static_cast<std::size_t>(n) * field.height);
        std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
        for (int r = 0; r < field.height; ++r)
          for (int i = 0; i < n; ++i)
            field.heights[static_cast<std::size_t>(r) * n + i] =
                kind == std::string("random_extent") ? uniform(rng) : profiles[r][i * (n_max / n)];
        for (const NamedTuning& t : tunings()) {
          if (t.name != "plain" && t.name != "default") continue;
          IntervisibilityOptions options;
          options.directions = 1;  // azimuth 0: one line per row, n samples each
          options.tree = t.tuning;
          IntervisibilityOutputs outputs;
          outputs.statistics = true;
          const auto s = computeIntervisibility(context_, field, options, outputs).statistics;
          Row row;
          row["section"] = "vis_scale";
          row["content"] = kind;
          row["width"] = std::to_string(n);
          row["height"] = std::to_string(field.height);
          row["method"] = "tree";
          row["tuning"] = t.name;
          row["K"] = "1";
          row["n"] = std::to_string(n);
          addStatistics(row, s);
          row["t_per_line"] = num(s.lines ? double(s.iterations) / s.lines : 0.0);
          row["m_per_line"] = num(s.lines ? double(s.horizons) / s.lines : 0.0);
          out_.write(row);
        }
        say("[vis_scale] %s n=%d", kind.c_str(), n);
      }
    }
  }

  const ComputeContext& context_;
  const SuiteOptions& options_;
  VisibilityConfig config_;
  CsvWriter& out_;
  int cores_;
};

}  // namespace

std::vector<std::pair<std::string, int>> visibilityInputs(const std::string& mode) {
  const VisibilityConfig c = visibilityConfigFor(mode);
  std::vector<std::pair<std::string, int>> inputs;
  for (const auto& name : c.contents)
    if (name != "dem") inputs.emplace_back(name, c.n);
  return inputs;
}

int runVisibilitySuite(const ComputeContext& context, const SuiteOptions& options) {
  fs::create_directories(options.out_dir);
  const auto start = std::chrono::steady_clock::now();
  KeyValues environment = describeEnvironment(context.device());
  environment.emplace_back("mode", options.mode);
  environment.emplace_back("commit", options.commit);
  {
    CsvWriter out((fs::path(options.out_dir) / "visibility.csv").string(), kVisibilityColumns);
    VisibilitySuite(context, options, out).run();
  }
  environment.emplace_back("load_average_end", loadAverage());
  environment.emplace_back("suite_seconds",
                           num(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()));
  std::ofstream env(fs::path(options.out_dir) / "visibility_environment.txt");
  for (const auto& [k, v] : environment) env << k << " = " << v << "\n";
  say("visibility suite (%s) done in %s s", options.mode.c_str(), environment.back().second.c_str());
  return 0;
}

}  // namespace hfvis::bench
