// bench/suite.cpp: the standard suite. Sections (the `section` column of results.csv):
//   checks    the oracle's self-checks; the baselines and the host SVF/AO formulas against
//             the library on the same input
//   headline  N = 1024 (quick: 256), K = 64 on the fractal terrain: sweep against the naive
//             march (both with the K angle planes and with the SVF only), the bandwidth
//             floor and the sweep's denser sampling, with horizon and SVF errors
//   plane     every content, every method, every K: time and error (the speed/error plane),
//             the sweep at 1 and 4 samples per unit
//   sources   error against samples per unit, the naive march and the sweep side by side
//   azimuth   SVF / AO at K against K = 1024 (quick: 512) of the same method (azimuthal
//             discretisation)
//   scale_n, scale_k   time against N and K (the report fits the exponents)
//   stack     the hull stack's pops per sample and depth (host run of Algorithm 1)
//   lattice   the sweep's directions per K (angle planes: exact azimuths; SVF only:
//             quadrature): samples per receiver and period, what the sweep's cost follows
//   vectorize PoCL's vectorisation remarks for the march kernels
#include "suite.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "environment.hpp"
#include "ground_truth.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "core/lattice_geometry.hpp"
#include "core/opencl_context.hpp"
#include "suite_support.hpp"

namespace hfvis::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// ------------------------------------------------------------------------------------------
// What each mode measures.

struct Config {
  std::vector<std::string> contents;  // synthetic fields at plane_n (plus the DEM unless tiny)
  int plane_n = 512;
  std::vector<int> ks = {8, 16, 32, 64, 128, 256};
  std::vector<int> naive_ks;                      // K at which the naive march enters the plane
  std::vector<double> plane_sweep_spus = {1, 4};  // the sweep's samples per unit in the plane
  std::vector<int> radii = {16, 64};              // Radius baselines, pixels
  std::vector<int> pyramid_near = {8, 16};
  int headline_n = 1024, headline_k = 64;
  int scale_k_n = 512;  // time against K on the fractal terrain of this size
  std::vector<int> sweep_scale_ns, naive_scale_ns;
  int sweep_scale_k = 64, naive_scale_k = 8;
  double max_scale_run_seconds = 200.0;  // larger sizes of the N series are skipped
  std::vector<double> source_spus = {1, 2, 4, 8};
  int truth_receivers = 8192;
  int azimuth_reference_k = 1024;
  int stack_directions = 16;
  TimingPolicy policy;
  bool vectorize = true;
};

Config configFor(const std::string& mode) {
  Config c;
  if (mode == "full") {
    c.contents = {"fractal", "bricks", "sine", "blocks", "city_dsm", "city_holes"};
    c.plane_n = 256;
    c.naive_ks = {8, 16, 32, 64, 128, 256};
    c.headline_n = 1024;
    c.scale_k_n = 512;
    c.sweep_scale_ns = {256, 512, 1024, 2048, 4096};
    c.naive_scale_ns = {256, 512, 1024, 2048};
    c.source_spus = {1, 2, 4, 8};
    c.truth_receivers = 8192;
    c.azimuth_reference_k = 1024;
    c.policy = {2, 5, 2.0};
  } else if (mode == "quick") {
    c.contents = {"fractal", "bricks", "sine", "blocks", "city_dsm", "city_holes"};
    c.plane_n = 128;
    c.ks = {8, 32, 128};
    c.naive_ks = {8, 32, 128};
    c.headline_n = 256;
    c.scale_k_n = 256;
    c.sweep_scale_ns = {128, 256, 512};
    c.naive_scale_ns = {128, 256};
    c.source_spus = {1, 4};
    c.truth_receivers = 1024;
    c.azimuth_reference_k = 512;
    c.policy = {2, 3, 0.3};
    c.max_scale_run_seconds = 20.0;
  } else {  // tiny: the smoke test; every code path on fields of a few thousand pixels
    c.contents = {"sine", "noise", "city_dsm", "city_holes"};
    c.plane_n = 40;
    c.ks = {4, 8};
    c.naive_ks = {4, 8};
    c.radii = {4};
    c.pyramid_near = {4};
    c.headline_n = 48, c.headline_k = 8;
    c.scale_k_n = 48;
    c.sweep_scale_ns = {24, 48};
    c.naive_scale_ns = {24, 48};
    c.sweep_scale_k = 8, c.naive_scale_k = 4;
    c.max_scale_run_seconds = 0.0;  // exercises the skip: every size after the first
    c.source_spus = {1, 2};
    c.truth_receivers = 300;
    c.azimuth_reference_k = 32;
    c.stack_directions = 4;
    c.policy = {1, 1, 0.0};
    c.vectorize = false;
  }
  return c;
}

// ------------------------------------------------------------------------------------------
// results.csv: one row per measurement; columns a row does not use stay empty.

// clang-format off
const std::vector<std::string> kColumns = {
    "section", "content", "width", "height", "method", "outputs", "K", "spu", "param", "reps",
    "t_min_s", "t_median_s", "t_all_s", "cpu_min_s", "load_1min", "pixel_dirs", "core_ns_per_pd",
    "cpu_ns_per_pd", "steps_executed", "steps_inside", "core_ns_per_step", "cpu_ns_per_step", "err_samples",
    "err_nan", "err_mean_deg", "err_p99_deg", "err_max_deg", "err_bias_deg", "int_mean_deg", "int_p99_deg",
    "int_max_deg", "svf_mean_abs", "svf_max_abs", "ao_mean_abs", "ao_max_abs", "metric", "value", "note"};
// clang-format on

class Results : public CsvWriter {
 public:
  Results(const std::string& path, int cores) : CsvWriter(path, kColumns), cores_(cores) {}
  int cores() const { return cores_; }

 private:
  int cores_;
};

Row measurementRow(const std::string& section, const std::string& content, const HeightField& field,
                   const MethodSpec& spec, const Timing& timing, int cores) {
  Row row;
  row["section"] = section;
  row["content"] = content;
  row["width"] = std::to_string(field.width);
  row["height"] = std::to_string(field.height);
  row["method"] = spec.name();
  row["outputs"] = spec.outputs();
  row["K"] = std::to_string(spec.directions);
  row["spu"] = num(spec.samples_per_unit);
  row["param"] = std::to_string(spec.parameter);
  row["reps"] = std::to_string(timing.seconds.size());
  row["t_min_s"] = num(timing.min());
  row["t_median_s"] = num(timing.median());
  std::string all;
  for (double s : timing.seconds) all += (all.empty() ? "" : ";") + num(s);
  row["t_all_s"] = all;
  const double pd = static_cast<double>(field.pixelCount()) * spec.directions;
  row["cpu_min_s"] = num(timing.cpuMin());
  row["load_1min"] = loadAverage().substr(0, loadAverage().find(' '));
  row["pixel_dirs"] = num(pd);
  row["core_ns_per_pd"] = num(timing.min() * cores / pd * 1e9);
  row["cpu_ns_per_pd"] = num(timing.cpuMin() / pd * 1e9);
  return row;
}

void addErrors(Row& row, const ErrorStats& e) {
  row["err_samples"] = std::to_string(e.samples);
  row["err_nan"] = std::to_string(e.nan_samples);
  row["err_mean_deg"] = num(e.mean_deg);
  row["err_p99_deg"] = num(e.p99_deg);
  row["err_max_deg"] = num(e.max_deg);
  row["err_bias_deg"] = num(e.bias_deg);
  row["int_mean_deg"] = num(e.interior_mean_deg);
  row["int_p99_deg"] = num(e.interior_p99_deg);
  row["int_max_deg"] = num(e.interior_max_deg);
  row["svf_mean_abs"] = num(e.svf_mean);
  row["svf_max_abs"] = num(e.svf_max);
  row["ao_mean_abs"] = num(e.ao_mean);
  row["ao_max_abs"] = num(e.ao_max);
}

bool isMarch(const MethodSpec& spec) {
  return spec.kind == MethodKind::Naive || spec.kind == MethodKind::Radius;
}

void addSteps(Row& row, const HeightField& field, const MethodSpec& spec, const Timing& timing, int cores) {
  if (!isMarch(spec)) return;
  const int limit = spec.kind == MethodKind::Radius
                        ? static_cast<int>(std::lround(spec.parameter * spec.samples_per_unit))
                        : 0;
  const MarchSteps steps =
      naiveMarchSteps(field, spec.directions, spec.samples_per_unit, baselineTileX(), baselineTileY(), limit);
  row["steps_executed"] = num(steps.executed);
  row["steps_inside"] = num(steps.inside);
  row["core_ns_per_step"] = num(timing.min() * cores / steps.executed * 1e9);
  row["cpu_ns_per_step"] = num(timing.cpuMin() / steps.executed * 1e9);
}

Row metricRow(const std::string& section, const std::string& content, const HeightField* field,
              const std::string& metric, double value, const std::string& note = "") {
  Row row;
  row["section"] = section;
  row["content"] = content;
  if (field) {
    row["width"] = std::to_string(field->width);
    row["height"] = std::to_string(field->height);
  }
  row["metric"] = metric;
  row["value"] = num(value);
  row["note"] = note;
  return row;
}

// ------------------------------------------------------------------------------------------
// Inputs.

std::string describe(const MethodSpec& spec) {
  std::ostringstream s;
  s << spec.name() << " (" << spec.outputs() << ") K=" << spec.directions;
  if (spec.samples_per_unit != 1.0) s << " spu=" << spec.samples_per_unit;
  return s.str();
}

MethodSpec spec(MethodKind kind, int k, bool angles = true, int parameter = 0, double spu = 1.0) {
  MethodSpec s;
  s.kind = kind;
  s.directions = k;
  s.angles = angles;
  s.parameter = parameter;
  s.samples_per_unit = spu;
  return s;
}

// ------------------------------------------------------------------------------------------
// The suite.

class Suite {
 public:
  Suite(const ComputeContext& context, const SuiteOptions& options, Results& results)
      : context_(context), options_(options), config_(configFor(options.mode)), results_(results) {}

  void run() {
    checks();
    plane();
    sources();
    azimuth();
    stack();
    lattice();
    headline();
    scaling();
    if (config_.vectorize) vectorize();
  }

 private:
  // Times one method, writes its row (with errors when a truth is given: horizon errors
  // from the angle planes, or the SVF error of an SVF-only run), returns the output.
  MethodOutput timed(const std::string& section, const Content& content, const MethodSpec& s,
                     const GroundTruth* truth, Row* written = nullptr) {
    Measured m = measureMethod(context_, content.field, s, config_.policy);
    Row row = measurementRow(section, content.name, content.field, s, m.timing, results_.cores());
    addSteps(row, content.field, s, m.timing, results_.cores());
    std::string error_text;
    char text[128];
    if (truth && s.angles && !m.output.angles.empty()) {
      const ErrorStats e = horizonErrors(content.field, *truth, m.output.angles, s.directions);
      addErrors(row, e);
      std::snprintf(text, sizeof text, ", error mean %.3f p99 %.3f max %.2f deg, SVF mean %.2e max %.2e",
                    e.mean_deg, e.p99_deg, e.max_deg, e.svf_mean, e.svf_max);
      error_text = text;
    } else if (truth && !m.output.svf.empty()) {
      const SvfErrorStats e = svfErrors(content.field, *truth, m.output.svf, s.directions);
      row["svf_mean_abs"] = num(e.mean_abs);
      row["svf_max_abs"] = num(e.max_abs);
      row["note"] = "SVF output against the exact horizons' SVF (K = " + std::to_string(s.directions) +
                    ", azimuths 2 pi k / K) on " + std::to_string(e.receivers) + " receivers; bias " +
                    num(e.bias);
      std::snprintf(text, sizeof text, ", SVF error mean %.2e max %.2e (bias %.2e)", e.mean_abs, e.max_abs,
                    e.bias);
      error_text = text;
    }
    results_.write(row);
    if (written) *written = row;
    say("[%s] %s %s: min %.4f s, median %.4f s (%zu runs), %s core-ns/pd%s", section.c_str(),
        content.label.c_str(), describe(s).c_str(), m.timing.min(), m.timing.median(),
        m.timing.seconds.size(), row["core_ns_per_pd"].c_str(), error_text.c_str());
    return std::move(m.output);
  }

  GroundTruth truthFor(const Content& content, int directions) {
    const GroundTruth t = cachedGroundTruth(content.field, content.label, directions, config_.truth_receivers,
                                            threads(), options_.cache_dir);
    const std::size_t nodata = content.field.nodataCount();
    const std::string holes =
        nodata ? "; nodata " + num(100.0 * double(nodata) / double(content.field.pixelCount())) + " %" : "";
    Row row = metricRow("truth", content.name, &content.field, t.from_cache ? "cached" : "computed_seconds",
                        t.seconds,
                        std::to_string(t.receivers.size()) + " receivers x " + std::to_string(t.directions) +
                            " directions" + holes);
    results_.write(row);
    say("[truth] %s: %zu receivers x %d directions (%s)%s", content.label.c_str(), t.receivers.size(),
        t.directions, t.from_cache ? "from cache" : (num(t.seconds) + " s").c_str(), holes.c_str());
    return t;
  }

  void checks() {
    std::string summary;
    const auto failures = checkGroundTruth(&summary);
    results_.write(metricRow("checks", "", nullptr, "truth_self_check_failures", failures.size(), summary));
    for (const auto& f : failures) say("[checks] ground truth check FAILED: %s", f.c_str());
    say("[checks] %s", summary.c_str());
    if (!failures.empty()) throw Error("the ground truth failed its self-checks");

    // The baselines' march (radius_march, what radius_R runs) with a radius past every ray's
    // end against the library's naive march: the same method, so radius_R is the library's
    // march cut short (rounding may differ). Then the host SVF / AO formulas against the
    // library's reduction, on the same input.
    // K = 16: directions off the grid's axes and diagonals, where the sweep's lattice steps
    // are not at 2 pi k / K exactly.
    const Content c = loadContent(options_, config_.contents.front(), config_.plane_n);
    const int k = 16;
    const int whole = c.field.width + c.field.height;
    const MethodOutput baseline = runMethod(context_, c.field, spec(MethodKind::Radius, k, true, whole));
    const MethodOutput library = runMethod(context_, c.field, spec(MethodKind::Naive, k));
    const PlaneDifference naive = planeDifference(baseline.angles, library.angles);
    results_.write(metricRow("checks", c.name, &c.field, "baseline_march_vs_library_naive_max_deg",
                             naive.max_abs * 180.0 / M_PI,
                             "K=" + std::to_string(k) + ", radius_" + std::to_string(whole)));
    say("[checks] baseline march (radius_%d) vs library naive, K=%d: max difference %.3g deg", whole, k,
        naive.max_abs * 180.0 / M_PI);

    HorizonOptions o;
    o.directions = k;
    HorizonOutputs out;
    out.horizon_angles = out.sky_view_factor = out.ambient_occlusion = true;
    const HorizonResult r = computeHorizons(context_, c.field, o, out);
    double svf_diff = 0.0, ao_diff = 0.0;
    std::vector<double> e(k);
    const std::size_t plane = c.field.pixelCount();
    for (std::size_t p = 0; p < plane; ++p) {
      for (int d = 0; d < k; ++d) e[d] = r.angles[d * plane + p];
      const Normal n =
          surfaceNormal(c.field, static_cast<int>(p % c.field.width), static_cast<int>(p / c.field.width));
      // With the angle planes the library takes the directions within its azimuth tolerance
      // of 2 pi k / K, weighted 1/K: the AO formula needs the azimuths it used.
      svf_diff = std::max(svf_diff, std::abs(skyViewFactor(e) - r.sky_view_factor[p]));
      ao_diff = std::max(ao_diff, std::abs(ambientOcclusion(e, n, r.azimuths) - r.ambient_occlusion[p]));
    }
    results_.write(metricRow("checks", c.name, &c.field, "host_svf_vs_library_max_abs", svf_diff));
    results_.write(metricRow("checks", c.name, &c.field, "host_ao_vs_library_max_abs", ao_diff));
    say("[checks] host SVF / AO formulas vs the library's reduction: max difference %.3g / %.3g", svf_diff,
        ao_diff);
    if (svf_diff > 1e-4 || ao_diff > 1e-4)
      throw Error("the host SVF / AO formulas disagree with the library");
  }

  void headline() {
    const Content c = loadContent(options_, "fractal", config_.headline_n);
    const int k = config_.headline_k;
    const GroundTruth truth = truthFor(c, k);
    const std::string s = "headline";
    timed(s, c, spec(MethodKind::Sweep, k), &truth);
    timed(s, c, spec(MethodKind::Sweep, k, false), &truth);  // SVF only: its SVF error
    timed(s, c, spec(MethodKind::Floor, k), nullptr);
    timed(s, c, spec(MethodKind::Floor, k, false), nullptr);
    timed(s, c, spec(MethodKind::Naive, k), &truth);
    timed(s, c, spec(MethodKind::Naive, k, false), &truth);
    for (double spu : {2.0, 4.0}) timed(s, c, spec(MethodKind::Sweep, k, true, 0, spu), &truth);
    timed(s, c, spec(MethodKind::Radius, k, true, config_.radii.back()), &truth);
    timed(s, c, spec(MethodKind::Pyramid, k, true, config_.pyramid_near.back()), &truth);
  }

  std::vector<Content> planeContents() {
    std::vector<Content> all;
    for (const auto& name : config_.contents) all.push_back(loadContent(options_, name, config_.plane_n));
    all.push_back(loadContent(options_, "dem", config_.plane_n));
    return all;
  }

  void plane() {
    for (const Content& c : planeContents()) {
      const int k_max = *std::max_element(config_.ks.begin(), config_.ks.end());
      const GroundTruth truth = truthFor(c, k_max);
      for (int k : config_.ks) {
        for (double spu : config_.plane_sweep_spus)
          timed("plane", c, spec(MethodKind::Sweep, k, true, 0, spu), &truth);
        if (std::count(config_.naive_ks.begin(), config_.naive_ks.end(), k))
          timed("plane", c, spec(MethodKind::Naive, k), &truth);
        if (c.field.nodataCount() > 0) continue;  // (the baselines take no nodata)
        for (int r : config_.radii) timed("plane", c, spec(MethodKind::Radius, k, true, r), &truth);
        for (int p : config_.pyramid_near) timed("plane", c, spec(MethodKind::Pyramid, k, true, p), &truth);
      }
    }
  }

  // Error against samples per unit, on the fractal terrain, the DEM and the city DSM at K = 64
  // (tiny: 8):
  // the naive march (its sampling error alone: steps of 1/S pixel) and the sweep (the exact
  // grid crossings, and with S > 1 about S samples per pixel between them).
  void sources() {
    const int k = options_.mode == "tiny" ? 8 : 64;
    for (const std::string name : {"fractal", "dem", "city_dsm"}) {
      const Content c = loadContent(options_, name, config_.plane_n);
      const GroundTruth truth = truthFor(c, *std::max_element(config_.ks.begin(), config_.ks.end()));
      for (double spu : config_.source_spus) {
        timed("sources", c, spec(MethodKind::Naive, k, true, 0, spu), &truth);
        timed("sources", c, spec(MethodKind::Sweep, k, true, 0, spu), &truth);
      }
    }
  }

  // SVF / AO at K against K = azimuth_reference_k, same method (the sweep), whole field.
  void azimuth() {
    for (const Content& c : planeContents()) {
      const ShadingOutput reference =
          runShading(context_, c.field, MethodKind::Sweep, config_.azimuth_reference_k);
      for (int k : config_.ks) {
        const ShadingOutput at = runShading(context_, c.field, MethodKind::Sweep, k);
        const PlaneDifference svf = planeDifference(at.svf, reference.svf);
        const PlaneDifference ao = planeDifference(at.ao, reference.ao);
        Row row =
            metricRow("azimuth", c.name, &c.field, "svf_ao_vs_reference_k", config_.azimuth_reference_k);
        row["method"] = "sweep";
        row["K"] = std::to_string(k);
        row["svf_mean_abs"] = num(svf.mean_abs);
        row["svf_max_abs"] = num(svf.max_abs);
        row["ao_mean_abs"] = num(ao.mean_abs);
        row["ao_max_abs"] = num(ao.max_abs);
        results_.write(row);
        say("[azimuth] %s K=%d vs K=%d: SVF mean %.2e max %.2e, AO mean %.2e max %.2e", c.label.c_str(), k,
            config_.azimuth_reference_k, svf.mean_abs, svf.max_abs, ao.mean_abs, ao.max_abs);
      }
    }
  }

  void scaling() {
    // Time against N: the sweep (SVF only: what the kernels cost, no K planes to download)
    // at sweep_scale_k, and the sweep and the library's naive march (both SVF only, the
    // whole library call) at naive_scale_k, so each N has a same-K ratio. "As far as the machine allows":
    // a size whose run, extrapolated from the size before (N^2 for the sweep, N^3 for the
    // march), would exceed max_scale_run_seconds is skipped, and the skip is recorded.
    std::map<std::string, std::pair<int, double>> last;  // series -> (N, seconds) measured last
    auto scaled = [&](const Content& c, const MethodSpec& s, double power) {
      const std::string series = s.name() + "/" + std::to_string(s.directions);
      const auto it = last.find(series);
      if (it != last.end()) {
        const double predicted =
            it->second.second * std::pow(double(c.field.width) / it->second.first, power);
        if (predicted > config_.max_scale_run_seconds) {
          Row row =
              metricRow("scale_n", c.name, &c.field, "skipped_predicted_seconds", predicted,
                        "one run extrapolated from N = " + std::to_string(it->second.first) +
                            " exceeds the mode's limit of " + num(config_.max_scale_run_seconds) + " s");
          row["method"] = s.name();
          row["outputs"] = s.outputs();
          row["K"] = std::to_string(s.directions);
          results_.write(row);
          say("[scale_n] %s %s: skipped, one run would take about %.0f s", c.label.c_str(),
              describe(s).c_str(), predicted);
          return;
        }
      }
      Row row;
      timed("scale_n", c, s, nullptr, &row);
      last[series] = {c.field.width, std::stod(row["t_min_s"])};
    };
    for (int n : config_.sweep_scale_ns) {
      const Content c = loadContent(options_, "fractal", n);
      scaled(c, spec(MethodKind::Sweep, config_.sweep_scale_k, false), 2.0);
      if (std::count(config_.naive_scale_ns.begin(), config_.naive_scale_ns.end(), n)) {
        scaled(c, spec(MethodKind::Sweep, config_.naive_scale_k, false), 2.0);
        scaled(c, spec(MethodKind::Naive, config_.naive_scale_k, false), 3.0);
      }
    }
    // Time against K (the plane has every method against K at its size).
    const Content c = loadContent(options_, "fractal", config_.scale_k_n);
    for (int k : config_.ks) timed("scale_k", c, spec(MethodKind::Sweep, k, false), nullptr);
  }

  void stack() {
    std::vector<Content> contents = planeContents();
    contents.push_back(loadContent(options_, "fractal", config_.headline_n));
    for (const Content& c : contents) {
      if (c.field.nodataCount() > 0) continue;  // (the statistics' replay of the stack takes no nodata)
      const StackStats s = hullStackStatistics(c.field, config_.stack_directions);
      const std::string note =
          std::to_string(config_.stack_directions) + " directions, " + std::to_string(s.samples) + " samples";
      results_.write(metricRow("stack", c.name, &c.field, "pops_per_sample", s.pops_per_sample, note));
      results_.write(metricRow("stack", c.name, &c.field, "mean_depth", s.mean_depth, note));
      results_.write(metricRow("stack", c.name, &c.field, "max_depth", s.max_depth, note));
      results_.write(metricRow("stack", c.name, &c.field, "samples_per_receiver",
                               s.receivers ? double(s.samples) / s.receivers : 0.0, note));
      say("[stack] %s: %.3f pops per sample, mean depth %.2f, max depth %d, %.2f samples per receiver",
          c.label.c_str(), s.pops_per_sample, s.mean_depth, s.max_depth,
          s.receivers ? double(s.samples) / s.receivers : 0.0);
    }
  }

  // The directions the sweep takes at each K, as the library chooses them, on a square-cell
  // field (the fractal) and the DEM (its cells are not square): per receiver and direction
  // the sweep pushes one period's samples, so its cost per pixel-direction follows
  // samples_per_receiver (host only, no timing).
  void lattice() {
    std::vector<int> ks = config_.ks;
    if (!std::count(ks.begin(), ks.end(), config_.headline_k)) ks.push_back(config_.headline_k);
    std::sort(ks.begin(), ks.end());
    for (const std::string name : {"fractal", "dem", "city_dsm"}) {
      const Content c = loadContent(options_, name, config_.plane_n);
      for (int k : ks) {
        for (const bool angles : {true, false}) {
          HorizonOptions o;
          o.directions = k;
          const auto directions = detail::latticeDirections(c.field, o, angles, o.azimuth_tolerance);
          double period = 0.0, longest = 0.0, offset = 0.0;
          int a_max = 0, b_max = 0;
          for (std::size_t q = 0; q < directions.size(); ++q) {
            const auto& d = directions[q];
            period += d.period / directions.size();
            if (d.period > longest) longest = d.period, a_max = d.a, b_max = d.b;
            offset = std::max(offset, std::abs(d.azimuth - directionAzimuth(static_cast<int>(q), o)));
          }
          for (double spu : {1.0, 4.0}) {
            double samples = 0.0, most = 0.0;
            for (const auto& d : directions) {
              const double n = static_cast<double>(detail::latticeSamples(d, spu).size());
              samples += n / directions.size();
              most = std::max(most, n);
            }
            char note[200];
            std::snprintf(note, sizeof note,
                          "max %g samples; period mean %.2f px, max %.2f px (step %d, %d); largest azimuth "
                          "offset %.3g deg",
                          most, period, longest, a_max, b_max, offset * 180.0 / M_PI);
            Row row = metricRow("lattice", c.name, &c.field, "samples_per_receiver", samples, note);
            row["method"] = "sweep";
            row["outputs"] = angles ? "angles" : "svf";
            row["K"] = std::to_string(k);
            row["spu"] = num(spu);
            results_.write(row);
            say("[lattice] %s K=%d %s spu=%g: %.2f samples per receiver (%s)", c.label.c_str(), k,
                angles ? "angles" : "svf", spu, samples, note);
          }
        }
      }
    }
  }

  void vectorize() {
    const std::string remarks = vectorizationRemarks(options_.self_path);
    std::istringstream lines(remarks);
    for (std::string line; std::getline(lines, line);) {
      const auto colon = line.find(": ");
      if (colon == std::string::npos) continue;
      Row row;
      row["section"] = "vectorize";
      row["method"] = line.substr(0, colon);
      row["metric"] = "remark";
      row["note"] = line.substr(colon + 2);
      results_.write(row);
      say("[vectorize] %s", line.c_str());
    }
  }

  const ComputeContext& context_;
  const SuiteOptions& options_;
  Config config_;
  Results& results_;
};

// Source lines (1-based) of `file` as embedded (the library's kernels, or the benchmark's own);
// for naming the loops PoCL remarks on.
std::vector<std::string> embeddedLines(const std::string& file) {
  std::string include_dir;
  const auto& bench = detail::benchKernelSources();
  const auto own = bench.find(file);
  std::istringstream in(own != bench.end() ? own->second : detail::kernelSource(file, "", &include_dir));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace

Measured measureMethod(const ComputeContext& context, const HeightField& field, const MethodSpec& spec,
                       const TimingPolicy& policy) {
  Measured m;
  m.timing = timeWithWarmUp([&] { runMethod(context, crop(field, 64, 64), spec); },
                            [&] {
                              m.output = MethodOutput{};  // free the previous output first, as a fresh process would
                              m.output = runMethod(context, field, spec);
                            },
                            policy);
  return m;
}

int runKernelsOnce(const ComputeContext& context, const std::string& which) {
  HeightField field = makeSyntheticField("noise", 96, 80, 5);
  const bool library = which == "all" || which == "library", bench = which == "all" || which == "bench";
  if (library) runMethod(context, field, spec(MethodKind::Naive, 8));
  if (bench) {
    runMethod(context, field, spec(MethodKind::Radius, 8, true, 32));  // radius_march
    runMethod(context, field, spec(MethodKind::Pyramid, 8, true, 16));
  }
  return 0;
}

std::string vectorizationRemarks(const std::string& self_path) {
  std::ostringstream report;
  for (const std::string which : {"library", "bench"}) {
    const std::string file = which == std::string("library") ? "horizon.cl" : "horizon_baselines.cl";
    const fs::path log_path =
        fs::temp_directory_path() / ("hfvis_bench_remarks_" + std::to_string(getpid()) + ".txt");
    // Debug lines make PoCL's remarks name the source line; its kernel cache off makes it
    // compile (and remark) at all.
    const fs::path cache = fs::temp_directory_path() / ("hfvis_bench_pocl_" + std::to_string(getpid()));
    const std::string command =
        "POCL_VECTORIZER_REMARKS=1 POCL_KERNEL_CACHE=0 POCL_EXTRA_BUILD_FLAGS=-g POCL_CACHE_DIR='" +
        cache.string() + "' '" + self_path + "' vectorize-run " + which + " > '" + log_path.string() +
        "' 2>&1";
    const int status = std::system(command.c_str());
    fs::remove_all(cache);
    std::ifstream in(log_path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    fs::remove(log_path);
    // PoCL names the compiled file by its cache path, absolute or relative to the working
    // directory; replaced by a marker, the path cannot run into the previous remark's text.
    std::error_code ignored;
    const std::vector<std::string> paths = {
        cache.string(), fs::relative(cache, fs::current_path(), ignored).string(), cache.filename().string()};
    for (const std::string& path : paths) {
      for (std::size_t at; !path.empty() && (at = text.find(path)) != std::string::npos;)
        text.replace(at, path.size(), "@");
    }
    if (status != 0) {
      report << which << ": the child run failed (status " << status << ")\n";
      continue;
    }
    const std::vector<std::string> source = embeddedLines(file);
    // Remarks run together without newlines: "<path>.cl:LINE:COL: text<unknown>:0:0: text...".
    // Split the log at each location; loops PoCL generates (work-item loops) have no line.
    const std::regex location(R"((<unknown>|@[^\s:<]*\.cl):(\d+):\d+: )");
    std::vector<std::smatch> found;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), location); it != std::sregex_iterator();
         ++it)
      found.push_back(*it);
    std::set<std::string> seen;
    std::map<std::string, int> generated;  // remark on PoCL-generated loops -> count
    for (std::size_t i = 0; i < found.size(); ++i) {
      const auto begin = found[i].position(0) + found[i].length(0);
      const auto end =
          i + 1 < found.size() ? found[i + 1].position(0) : static_cast<std::ptrdiff_t>(text.size());
      std::string what = text.substr(begin, end - begin);
      if (what.rfind("vectorized loop", 0) != 0 && what.rfind("loop not vectorized", 0) != 0) continue;
      if (const auto paren = what.find(", interleaved"); paren != std::string::npos)
        what = what.substr(0, paren) + ")";
      const int line = std::stoi(found[i][2]);
      if (found[i][1] == "<unknown>") {
        ++generated[what];
        continue;
      }
      std::string code = line >= 1 && line <= static_cast<int>(source.size()) ? source[line - 1] : "";
      code.erase(0, code.find_first_not_of(' '));
      if (code.size() > 70) code = code.substr(0, 67) + "...";
      const std::string entry =
          which + " " + file + ": line " + std::to_string(line) + " `" + code + "`: " + what;
      if (seen.insert(entry).second) report << entry << "\n";
    }
    for (const auto& [what, count] : generated)
      report << which << " " << file << ": PoCL-generated loops (no source line): " << what << " (" << count
             << " times)\n";
    if (seen.empty()) report << which << " " << file << ": no loop remarks (is the driver PoCL?)\n";
  }
  return report.str();
}

std::vector<std::pair<std::string, int>> requiredInputs(const std::string& mode) {
  const Config c = configFor(mode);
  std::set<std::pair<std::string, int>> inputs;
  for (const auto& name : c.contents)
    if (name != "city_dsm" && name != "city_holes")
      inputs.emplace(name, c.plane_n);   // generated in loadContent
  inputs.emplace("fractal", c.plane_n);  // the error sources study
  inputs.emplace("fractal", c.headline_n);
  inputs.emplace("fractal", c.scale_k_n);
  for (int n : c.sweep_scale_ns) inputs.emplace("fractal", n);
  for (int n : c.naive_scale_ns) inputs.emplace("fractal", n);
  return {inputs.begin(), inputs.end()};
}

int runSuite(const ComputeContext& context, const SuiteOptions& options) {
  fs::create_directories(options.out_dir);
  const auto start = Clock::now();
  KeyValues environment = describeEnvironment(context.device());
  environment.emplace_back("mode", options.mode);
  environment.emplace_back("commit", options.commit);
  environment.emplace_back("sweep_azimuth_tolerance_deg", num(HorizonOptions{}.azimuth_tolerance * 180.0 / M_PI));
  const int cores = std::max(1, context.device().compute_units);
  {
    Results results((fs::path(options.out_dir) / "results.csv").string(), cores);
    Suite(context, options, results).run();
  }
  environment.emplace_back("load_average_end", loadAverage());
  environment.emplace_back("suite_seconds", num(std::chrono::duration<double>(Clock::now() - start).count()));
  std::ofstream env(fs::path(options.out_dir) / "environment.txt");
  for (const auto& [k, v] : environment) env << k << " = " << v << "\n";
  say("suite (%s) done in %s s: %s", options.mode.c_str(), environment.back().second.c_str(),
      (fs::path(options.out_dir) / "results.csv").string().c_str());
  return 0;
}

}  // namespace hfvis::bench
