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
//   vis_accuracy  issues 8 (target e) and 25: the visible counts of the hull tree (default
//              options) and of the naive per-pixel unit march against dense reference marches
//              (bench/dense_visibility.hpp, D samples per pixel length), per K: along each
//              method's own directions (rel_err_*) and dense in azimuth (azd_*, the integral
//              the counts estimate): per-pixel relative error |count - ref| / ref, mean over
//              the pixels (issue 8: the tree's at most 1.1 x the naive march's, same
//              directions; issue 25: the tree's no worse than the naive march's at K >= 64,
//              dense in azimuth) and aggregate sum |count - ref| / sum ref; on small crops of
//              the synthetic fields, the DEM, a city-like surface model and the city DSM hard
//              case, with the two methods' times
// `--sections` picks some of them (time = vis_time, stats, zone, scale, accuracy).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <random>
#include <tuple>

#include "dense_visibility.hpp"
#include "environment.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "core/hull_tree.hpp"
#include "metrics.hpp"
#include "suite_support.hpp"

namespace hfvis::bench {
namespace {

namespace fs = std::filesystem;

struct VisibilityConfig {
  std::vector<std::string> contents = {"fractal", "bricks", "sine", "blocks", "dem"};
  int n = 1024;       // synthetic fields are n x n; the DEM is used whole (403 x 344)
  int time_k = 16;    // K of the timed runs (tree and naive)
  int stats_k = 16;   // K of the statistics (statistics runs read every line sample's horizons)
  std::vector<int> zone_steps = {1, 4, 16, 64, 256};
  std::vector<std::string> zone_contents = {"fractal", "dem"};
  std::vector<int> scale_ns;  // line lengths of the scaling study
  int scale_lines = 64;       // lines per length
  int rounds = 3;             // vis_time: timed runs of each tree tuning ...
  int naive_rounds = 2;       // ... and of the naive march (interleaved)
  TimingPolicy policy;        // vis_zone
  // vis_accuracy: n x n crops (the DEM's centre; the cities generated at that size), each K of
  // accuracy_ks, the dense references at dense_per_unit samples per pixel length (the one dense
  // in azimuth with azimuth_dense_dirs directions), the tree and the naive march timed
  // accuracy_rounds times each, interleaved.
  std::vector<std::string> accuracy_contents = {"fractal", "bricks", "sine",    "blocks",
                                                "dem",     "city",   "city_dsm"};
  int accuracy_n = 256;
  std::vector<int> accuracy_ks = {16, 64, 128};
  int dense_per_unit = 8;
  int azimuth_dense_dirs = 256;
  int accuracy_rounds = 2;
};

VisibilityConfig visibilityConfigFor(const std::string& mode) {
  VisibilityConfig c;
  if (mode == "full") {
    c.policy = {2, 3, 2.0};
    for (int n = 64; n <= 16384; n *= 2) c.scale_ns.push_back(n);
  } else if (mode == "quick") {
    c.n = 256;
    c.time_k = 8;
    c.accuracy_n = 128;
    c.accuracy_ks = {16, 64};
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
    c.accuracy_contents = {"sine", "fractal", "dem", "city", "city_dsm"};
    c.accuracy_n = 40;
    c.accuracy_ks = {8, 64};  // diagonals too (K = 4 runs along the axes, where the tree is exact)
    c.azimuth_dense_dirs = 128;
    c.policy = {1, 1, 0.0};
  }
  return c;
}

// clang-format off
const std::vector<std::string> kVisibilityColumns = {
    "section", "content", "width", "height", "method", "tuning", "zone_steps", "K", "reps", "t_min_s",
    "t_median_s", "t_all_s", "cpu_min_s", "load_1min", "pixel_dirs", "core_ns_per_pd", "cpu_ns_per_pd",
    "receivers", "lines", "m_a", "t_a", "visible_a", "naive_a", "skip_fraction", "lines_over_bound", "n",
    "t_per_line", "m_per_line", "dense_per_unit", "ref_mean", "count_mean", "rel_err_mean", "rel_err_agg",
    "rel_err_p99", "rel_err_max", "rel_bias_mean", "err_pixels", "ref_seconds", "differ_pixels",
    "offset_differ_pixels", "azd_dirs", "azd_ref_mean", "azd_rel_err_mean", "azd_rel_err_agg", "azd_rel_err_p99",
    "azd_rel_bias_mean", "note"};
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
        cores_(std::max(1, context.device().compute_units)) {
    if (!options.accuracy_contents.empty()) config_.accuracy_contents = options.accuracy_contents;
    if (!options.accuracy_ks.empty()) config_.accuracy_ks = options.accuracy_ks;
  }

  // Runs the sections options.sections names (all when empty); records each part's seconds
  // in `environment`.
  void run(KeyValues& environment) {
    const auto want = [&](const std::string& section) {
      return options_.sections.empty() ||
             std::count(options_.sections.begin(), options_.sections.end(), section) > 0;
    };
    const auto seconds_since = [](std::chrono::steady_clock::time_point start) {
      return num(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    };
    auto start = std::chrono::steady_clock::now();
    if (want("time") || want("stats") || want("zone")) {
      for (const auto& name : config_.contents) {
        const Content content = loadContent(options_, name, config_.n);
        if (want("time")) timeContent(content);
        if (want("stats")) statistics(content);
        if (want("zone") && std::count(config_.zone_contents.begin(), config_.zone_contents.end(), name))
          zone(content);
      }
      environment.emplace_back("time_stats_zone_seconds", seconds_since(start));
    }
    if (want("scale")) {
      start = std::chrono::steady_clock::now();
      scaling();
      environment.emplace_back("scale_seconds", seconds_since(start));
    }
    if (want("accuracy")) {
      start = std::chrono::steady_clock::now();
      accuracy();
      environment.emplace_back("accuracy_seconds", seconds_since(start));
      say("[vis_accuracy] section done in %s s", environment.back().second.c_str());
    }
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

  // Issue 8, target (e), and issue 25's count target: visible counts against the dense
  // references (see the file's head and bench/dense_visibility.hpp). Per content: the reference
  // dense in azimuth (azimuth_dense_dirs directions, D samples per pixel length), then per K the
  // references along each method's own directions (the naive march's phi_k, the tree's lattice
  // steps with their quadrature weights), the host unit march (the reference's code at D = 1:
  // the naive march's samples in double), the hull tree (default options, HullTree) and the
  // naive march (IntervisibilityMethod::Naive), both at samples_per_unit 1, timed
  // accuracy_rounds times each, interleaved (tree, naive, tree, naive); the counts of their
  // last runs are compared with the references.
  void accuracy() {
    for (const auto& name : config_.accuracy_contents) {
      const Content content = accuracyContent(name);
      const auto start = std::chrono::steady_clock::now();
      const int n = config_.azimuth_dense_dirs;
      const auto lengths = denseVisibleLengths(content.field, azimuthDenseRays(n), config_.dense_per_unit);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      say("[vis_accuracy] %s: reference dense in azimuth (%d directions, D = %d) in %.1f s",
          content.label.c_str(), n, config_.dense_per_unit, seconds);
      for (int k : config_.accuracy_ks) accuracyOf(content, k, lengths, seconds);
    }
  }

  Content accuracyContent(const std::string& name) const {
    const int n = config_.accuracy_n;
    if (name != "city" && name != "city_dsm") return loadContent(options_, name, n);
    Content c;
    c.name = name;
    // Tiny mode: odd, non-square, as the other tiny stand-ins.
    const int w = options_.mode == "tiny" ? n + 3 : n, h = options_.mode == "tiny" ? n - 2 : n;
    c.field = name == "city" ? makeCityField(w, h, 2013) : makeSyntheticField("city", w, h, 2013);
    c.label = name + "_" + std::to_string(c.field.width) + "x" + std::to_string(c.field.height);
    return c;
  }

  // Azimuth offset (radians) of the host unit march's convention check.
  static constexpr double kCheckOffset = 0.1;

  struct CountErrors {
    double ref_mean = 0, count_mean = 0;  // over the compared pixels
    double mean = 0, aggregate = 0, p99 = 0, max = 0, bias = 0;
    std::size_t pixels = 0, ref_zero = 0;
  };

  // Per-pixel relative error |count - ref| / ref over the pixels with ref > 0 (mean, p99, max,
  // signed mean), and the aggregate sum |count - ref| / sum ref over the same pixels.
  template <typename T>
  static CountErrors countErrors(const std::vector<T>& counts, const std::vector<double>& ref) {
    CountErrors e;
    std::vector<double> relative;
    double sum_ref = 0, sum_count = 0, sum_abs = 0, sum_signed = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      if (!(ref[i] > 0)) {
        ++e.ref_zero;
        continue;
      }
      const double c = counts[i], d = c - ref[i];
      relative.push_back(std::fabs(d) / ref[i]);
      sum_ref += ref[i], sum_count += c, sum_abs += std::fabs(d), sum_signed += d / ref[i];
    }
    e.pixels = relative.size();
    if (relative.empty()) return e;
    const double n = double(relative.size());
    e.ref_mean = sum_ref / n;
    e.count_mean = sum_count / n;
    e.aggregate = sum_abs / sum_ref;
    e.bias = sum_signed / n;
    double total = 0;
    for (double r : relative) total += r, e.max = std::max(e.max, r);
    e.mean = total / n;
    const std::size_t at =
        std::min(relative.size() - 1, static_cast<std::size_t>(0.99 * (relative.size() - 1) + 0.5));
    std::nth_element(relative.begin(), relative.begin() + at, relative.end());
    e.p99 = relative[at];
    return e;
  }

  // The same-direction errors (rel_err_*, against `ref` along the method's own directions) and,
  // where given, those against the reference dense in azimuth (azd_*).
  void addErrors(Row& row, const CountErrors& e, double ref_seconds,
                 const CountErrors* dense = nullptr) const {
    row["dense_per_unit"] = std::to_string(config_.dense_per_unit);
    row["ref_mean"] = num(e.ref_mean);
    row["count_mean"] = num(e.count_mean);
    row["rel_err_mean"] = num(e.mean);
    row["rel_err_agg"] = num(e.aggregate);
    row["rel_err_p99"] = num(e.p99);
    row["rel_err_max"] = num(e.max);
    row["rel_bias_mean"] = num(e.bias);
    row["err_pixels"] = std::to_string(e.pixels);
    row["ref_seconds"] = num(ref_seconds);
    std::string note;
    if (e.ref_zero) note = std::to_string(e.ref_zero) + " pixels with reference 0 left out";
    if (dense) {
      row["azd_dirs"] = std::to_string(config_.azimuth_dense_dirs);
      row["azd_ref_mean"] = num(dense->ref_mean);
      row["azd_rel_err_mean"] = num(dense->mean);
      row["azd_rel_err_agg"] = num(dense->aggregate);
      row["azd_rel_err_p99"] = num(dense->p99);
      row["azd_rel_bias_mean"] = num(dense->bias);
      if (dense->ref_zero)
        note += (note.empty() ? "" : "; ") + std::to_string(dense->ref_zero) +
                " pixels with reference 0 (dense in azimuth) left out";
    }
    if (!note.empty()) row["note"] = note;
  }

  // One content at K directions; `dense` holds the visible lengths along the directions of the
  // reference dense in azimuth (azimuthDenseRays), computed in `dense_seconds`.
  void accuracyOf(const Content& content, int k, const std::vector<std::vector<double>>& dense,
                  double dense_seconds) {
    const HeightField& field = content.field;
    SweepOptions sweep;
    sweep.directions = k;
    const int n = static_cast<int>(dense.size());
    std::vector<double> azimuth_dense(field.pixelCount(), 0.0);  // K times their mean
    for (const auto& lengths : dense)
      for (std::size_t i = 0; i < lengths.size(); ++i) azimuth_dense[i] += lengths[i] * k / n;
    // The naive march's directions, phi_k with weight 1 each; the tree's lattice steps with
    // their weights (times K: the count's scale), as computeIntervisibility takes them.
    std::vector<DenseRay> tree_rays;
    for (const detail::TreeDirection& d : detail::treeDirections(field, sweep))
      tree_rays.push_back({d.lattice.azimuth, k * d.lattice.weight});
    const auto start = std::chrono::steady_clock::now();
    // The naive march's azimuths 2 pi i / K are every (n / K)-th of the dense ones where K divides n.
    std::vector<double> ref(field.pixelCount(), 0.0);
    if (n % k == 0) {
      for (int i = 0; i < n; i += n / k)
        for (std::size_t p = 0; p < ref.size(); ++p) ref[p] += dense[i][p];
    } else {
      ref = denseVisibleCounts(field, sweep, config_.dense_per_unit);
    }
    const std::vector<double> tree_ref = denseVisibleCounts(field, tree_rays, config_.dense_per_unit);
    const double ref_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::vector<double> unit = denseVisibleCounts(field, sweep, 1);

    IntervisibilityOptions tree;  // the library's defaults: HullTree, default tuning, 1 sample per unit
    tree.directions = k;
    IntervisibilityOptions naive = tree;
    naive.method = IntervisibilityMethod::Naive;
    IntervisibilityOutputs outputs;
    outputs.visible_count = true;
    for (const auto* options : {&tree, &naive})  // builds and caches each program
      computeIntervisibility(context_, crop(field, 64, 64), *options, outputs);
    Timing tree_time, naive_time;
    std::vector<float> tree_counts, naive_counts;
    for (int round = 0; round < config_.accuracy_rounds; ++round) {
      for (auto [options, timing, counts] :
           {std::tuple{&tree, &tree_time, &tree_counts}, std::tuple{&naive, &naive_time, &naive_counts}}) {
        const Timing one = timeRepeated(
            [&] { *counts = computeIntervisibility(context_, field, *options, outputs).visible_count; },
            {1, 1, 0.0});
        timing->seconds.push_back(one.seconds[0]);
        timing->cpu_seconds.push_back(one.cpu_seconds[0]);
      }
    }

    const CountErrors tree_e = countErrors(tree_counts, tree_ref), naive_e = countErrors(naive_counts, ref);
    const CountErrors tree_d = countErrors(tree_counts, azimuth_dense),
                      naive_d = countErrors(naive_counts, azimuth_dense);
    Row row = timingRow("vis_accuracy", content, "tree", "default", 0, k, tree_time);
    addStatistics(row, statisticsOf(field, k, tree.tree));
    addErrors(row, tree_e, ref_seconds + dense_seconds, &tree_d);
    out_.write(row);
    row = timingRow("vis_accuracy", content, "naive", "", 0, k, naive_time);
    addErrors(row, naive_e, ref_seconds + dense_seconds, &naive_d);
    out_.write(row);
    // The host unit march: the reference's code at D = 1, i.e. the naive march's samples
    // decided in double (ties within the tolerance). Where it differs from the library's naive
    // march, the difference is the library's float sampling (or a convention bug). The sum over
    // K directions 2 pi k / K is the same for mirrored directions, so a wrong azimuth sign would
    // not show at offset 0: the convention check compares the two again at an azimuth offset.
    const auto differing = [](const std::vector<float>& library, const std::vector<double>& host,
                              double* mean) {
      std::size_t differ = 0;
      double sum = 0;
      for (std::size_t i = 0; i < host.size(); ++i) {
        const double d = std::fabs(double(library[i]) - host[i]);
        differ += d > 0.5;
        sum += d;
      }
      *mean = host.empty() ? 0.0 : sum / host.size();
      return differ;
    };
    double diff_mean = 0, offset_diff_mean = 0;
    const std::size_t differ = differing(naive_counts, unit, &diff_mean);
    IntervisibilityOptions naive_offset = naive;
    naive_offset.azimuth_offset = kCheckOffset;
    const std::size_t offset_differ =
        differing(computeIntervisibility(context_, field, naive_offset, outputs).visible_count,
                  denseVisibleCounts(field, naive_offset, 1), &offset_diff_mean);
    row = Row();
    row["section"] = "vis_accuracy";
    row["content"] = content.name;
    row["width"] = std::to_string(field.width);
    row["height"] = std::to_string(field.height);
    row["method"] = "host_unit";
    row["K"] = std::to_string(k);
    addErrors(row, countErrors(unit, ref), ref_seconds);
    row["differ_pixels"] = std::to_string(differ);
    row["offset_differ_pixels"] = std::to_string(offset_differ);
    row["note"] = "against the library's naive march: counts differ at " + std::to_string(differ) + " of " +
                  std::to_string(unit.size()) + " pixels, mean |difference| " + num(diff_mean) +
                  " samples; at azimuth offset " + num(kCheckOffset) + " rad at " +
                  std::to_string(offset_differ) + " pixels, mean |difference| " + num(offset_diff_mean);
    out_.write(row);
    say("[vis_accuracy] %s K=%d D=%d: mean relative error, same directions: tree %.4f, naive %.4f; dense in "
        "azimuth: tree %.4f, naive %.4f (tree / naive %.2f); time tree %.3f s, naive %.3f s; host unit march "
        "differs from naive at %zu pixels (%zu at an azimuth offset)",
        content.label.c_str(), k, config_.dense_per_unit, tree_e.mean, naive_e.mean, tree_d.mean,
        naive_d.mean, naive_d.mean > 0 ? tree_d.mean / naive_d.mean : 0.0, tree_time.min(), naive_time.min(),
        differ, offset_differ);
  }

  const ComputeContext& context_;
  const SuiteOptions& options_;
  VisibilityConfig config_;
  CsvWriter& out_;
  int cores_;
};

}  // namespace

const std::vector<std::string>& visibilitySections() {
  static const std::vector<std::string> names = {"time", "stats", "zone", "scale", "accuracy"};
  return names;
}

std::vector<std::pair<std::string, int>> visibilityInputs(const std::string& mode) {
  const VisibilityConfig c = visibilityConfigFor(mode);
  std::vector<std::pair<std::string, int>> inputs;
  for (const auto& name : c.contents)
    if (name != "dem") inputs.emplace_back(name, c.n);
  for (const auto& name : c.accuracy_contents)
    if (name != "dem" && name != "city" && name != "city_dsm") inputs.emplace_back(name, c.accuracy_n);
  return inputs;
}

int runVisibilitySuite(const ComputeContext& context, const SuiteOptions& options) {
  fs::create_directories(options.out_dir);
  const auto start = std::chrono::steady_clock::now();
  KeyValues environment = describeEnvironment(context.device());
  environment.emplace_back("mode", options.mode);
  environment.emplace_back("commit", options.commit);
  std::string sections;
  for (const auto& s : options.sections) sections += (sections.empty() ? "" : ",") + s;
  environment.emplace_back("sections", sections.empty() ? "all" : sections);
  {
    CsvWriter out((fs::path(options.out_dir) / "visibility.csv").string(), kVisibilityColumns);
    VisibilitySuite(context, options, out).run(environment);
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
