// bench/main.cpp: hfvis_bench, the benchmark harness's command line.
//
//   hfvis_bench suite [--quick | --tiny] --out DIR [--data DIR] [--dem FILE] [--cache DIR]
//                     [--commit TEXT]
//       the standard suite: writes DIR/results.csv and DIR/environment.txt
//       (bench/run_report.sh builds, generates inputs, runs this and writes bench/report/)
//   hfvis_bench run FIELD [--method M] [-k K] [--spu S] [--param P]
//                   [--outputs angles|svf|ao|device] [--max-distance D] [--reps N]
//       one method on one field: min and median time and core-ns per pixel-direction
//       (methods: sweep, naive, radius, pyramid, floor)
//   hfvis_bench visibility [--quick | --tiny] --out DIR [--data DIR] [--dem FILE] [--commit TEXT]
//                          [--sections LIST] [--accuracy-contents LIST] [--accuracy-ks LIST]
//       the intervisibility suite: writes DIR/visibility.csv and DIR/visibility_environment.txt;
//       --sections runs some of its sections (comma-separated: time, stats, zone, scale,
//       accuracy; default all); --accuracy-contents and --accuracy-ks (comma-separated) narrow
//       the accuracy section to those contents (fractal, bricks, sine, blocks, dem, city,
//       city_dsm) and K
//   hfvis_bench vis-run FIELD [--method tree|naive] [-k K] [--tuning plain|deferred|default|zone]
//                       [--zone-steps S] [--reps N]
//       visible counts by one method on one field: min and median time, statistics
//   hfvis_bench lighting-time --env ENV [-k K[,K...]] [--reps N] FIELD...
//       environment lighting (computeHorizons, irradiance only): the fastest of N runs per field and K
//   hfvis_bench lighting-error FIELD --env ENV [--samples M] [-k K[,K...]] [--rows R[,R...]]
//       environment lighting against a Monte-Carlo ray-traced reference: mean and 99th-percentile
//       relative error against K (the map's rows) and against the table's bands (the largest K)
//   hfvis_bench viewshed-agreement DEM --observer COL,ROW [--observer-height H] [--target-height T]
//                                  [--samples N] [--seed S] RASTER...
//       viewshed rasters (visible where > 0) against the exact sight-line test at N random targets:
//       the Jaccard index of the visible sets and the disagreements that graze
//   hfvis_bench viewshed-culling [--levels 1,2,3,4] [--reps N] FIELD...
//   hfvis_bench pvs-rays | pvs-recall ... city noise dem: the PVS ray caster and samplers (bench/pvs.sh)
//   hfvis_bench pvs-scalar ... city noise: the caster's shared source as C++ on one core, us per ray
//       and a checksum of every result (to compare two builds of the caster bit for bit)
//       Stewart's culling pyramid per field: preprocessing time, memory per finest level kept, and
//       for valley, ground-level and high observers the culled shares and the exact and culled
//       viewsheds' times (interleaved, the fastest of N)
//   hfvis_bench region [--sections arealight,pair,error] [--reps N] FIELD...
//       region visibility's backends timed interleaved: area lights against S, the light's size
//       and height (arealight-quick: S = 32 interleaved, the culled march alone at S = 1024);
//       region pairs against their size and distance; the visible fraction's error against a
//       Monte-Carlo reference; bitmask: the bitmask scatter against culled and viewsheds at S = 32
//       and 1024, and the bits its table leaves to the march against the table's size; crossover: the
//       culled march against the bitmask scatter against S and the light, the default's choice
//   hfvis_bench field NAME N OUT
//       writes the synthetic field NAME (testing's hard cases: city, sine, ...) of N x N pixels
//       to OUT (EXR or GeoTIFF), for timing the CLI on it (bench/cost_against.sh)
//   hfvis_bench inputs [--quick]
//       the generated fields both suites read, one "<content> <N>" per line
//   hfvis_bench check-truth
//       the ground truth's self-checks (analytic cases, convergence of a dense march)
//   hfvis_bench vectorize-report
//       PoCL's vectorisation remarks for the march kernels, by source line
//   hfvis_bench vectorize-run all|library|bench
//       runs the march kernels once (what vectorize-report re-runs under
//       POCL_VECTORIZER_REMARKS=1)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "error_target.hpp"
#include "ground_truth.hpp"
#include "hfvis/environment_light.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "lighting.hpp"
#include "methods.hpp"
#include "metrics.hpp"
#include "pvs_bench.hpp"
#include "region_visibility.hpp"
#include "suite.hpp"
#include "suite_support.hpp"
#include "viewshed_agreement.hpp"
#include "viewshed_culling.hpp"

namespace {

using namespace hfvis;
using namespace hfvis::bench;

constexpr const char* kUsage =
    "usage: hfvis_bench suite [--quick | --tiny] --out DIR [--data DIR] [--dem FILE] [--cache DIR] [--commit "
    "TEXT]\n"
    "       hfvis_bench run FIELD [--method sweep|naive|radius|pyramid|floor] [-k K] [--spu S] [--param P]\n"
    "                   [--outputs angles|svf|ao|device] [--max-distance D] [--reps N]\n"
    "       hfvis_bench visibility [--quick | --tiny] --out DIR [--data DIR] [--dem FILE] [--commit TEXT]\n"
    "                              [--sections time,stats,zone,scale,accuracy]\n"
    "                              [--accuracy-contents LIST] [--accuracy-ks LIST]\n"
    "       hfvis_bench lighting-time --env ENV [-k K[,K...]] [--reps N] FIELD...\n"
    "       hfvis_bench lighting-error FIELD --env ENV [--samples M] [-k K[,K...]] [--rows R[,R...]]\n"
    "       hfvis_bench vis-run FIELD [--method tree|naive] [-k K] [--tuning plain|deferred|default|zone]\n"
    "                           [--zone-steps S] [--reps N]\n"
    "       hfvis_bench viewshed-agreement DEM --observer COL,ROW [--observer-height H] [--target-height T]\n"
    "                                      [--samples N] [--seed S] RASTER...\n"
    "       hfvis_bench viewshed-culling [--levels 1,2,3,4] [--reps N] FIELD...\n"
    "       hfvis_bench error-target [--data DIR] [--dem FILE] [--size N] [--errors E,...] [--contents A,B]\n"
    "                                [--reference-k K] [--reps N] [--tile T] [--curve KMAX]\n"
    "                                [--output svf-ao|viewcount|horizon]   (horizon: --errors in degrees)\n"
    "       hfvis_bench pvs-rays [--size N] [--rays R] [--reps K] [--dem FILE] FIELD...\n"
    "       hfvis_bench pvs-scalar [--size N] [--rays R] [--reps K] [--dem FILE] FIELD...\n"
    "       hfvis_bench pvs-recall [--size N] [--view-cell C] [--tile T] [--samples N,N,...]\n"
    "                              [--check-rays R] [--methods agvs,sgvs,per-cell] [--reference yes|no]\n"
    "                              [--seeds S,S,...] [--estimate-entries N] [--inside yes|no]\n"
    "                              [--dem FILE] FIELD...   (FIELD: city, noise, dem)\n"
    "       hfvis_bench region [--sections arealight,arealight-quick,pair,pair-quick,error,bitmask,\n"
    "                          crossover]\n"
    "                          [--reps N] FIELD...\n"
    "       hfvis_bench field NAME N OUT\n"
    "       hfvis_bench inputs [--quick]\n"
    "       hfvis_bench check-truth\n"
    "       hfvis_bench vectorize-report\n"
    "       hfvis_bench vectorize-run all|library|bench\n";

struct Usage : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Options of the form --name VALUE, in any order after the positional arguments.
class Arguments {
 public:
  Arguments(int argc, char** argv, int first) {
    for (int i = first; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--quick" || a == "--tiny") {
        flags_.push_back(a);
      } else if (a.rfind("-", 0) == 0) {
        if (i + 1 >= argc) throw Usage(a + " needs a value");
        values_.emplace_back(a, argv[++i]);
      } else {
        positional_.push_back(a);
      }
    }
  }
  std::string get(const std::string& name, const std::string& fallback = "") {
    for (auto& [k, v] : values_)
      if (k == name) {
        used_.push_back(k);
        return v;
      }
    return fallback;
  }
  bool flag(const std::string& name) const {
    for (const auto& f : flags_)
      if (f == name) return true;
    return false;
  }
  const std::vector<std::string>& positional() const { return positional_; }
  void rejectUnused() const {
    for (const auto& [k, v] : values_) {
      bool used = false;
      for (const auto& u : used_) used = used || u == k;
      if (!used) throw Usage("unknown option " + k);
    }
  }

 private:
  std::vector<std::pair<std::string, std::string>> values_;
  std::vector<std::string> flags_, positional_, used_;
};

double number(const std::string& text, const std::string& what) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw Usage(what + " must be a number (got '" + text + "')");
}

MethodKind methodKind(const std::string& name) {
  if (name == "sweep") return MethodKind::Sweep;
  if (name == "naive") return MethodKind::Naive;
  if (name == "radius") return MethodKind::Radius;
  if (name == "pyramid") return MethodKind::Pyramid;
  if (name == "floor") return MethodKind::Floor;
  throw Usage("unknown method '" + name + "'");
}

int runOne(Arguments& args) {
  if (args.positional().size() != 1) throw Usage("run takes one height field");
  MethodSpec spec;
  spec.kind = methodKind(args.get("--method", "sweep"));
  spec.directions = static_cast<int>(number(args.get("-k", "64"), "-k"));
  spec.samples_per_unit = number(args.get("--spu", "1"), "--spu");
  spec.parameter =
      static_cast<int>(number(args.get("--param", spec.kind == MethodKind::Radius ? "32" : "16"), "--param"));
  const std::string outputs = args.get("--outputs", "angles");
  if (outputs != "angles" && outputs != "svf" && outputs != "ao" && outputs != "device")
    throw Usage("--outputs: angles, svf, ao or device");
  spec.angles = outputs == "angles";
  spec.ambient_occlusion = outputs == "ao";
  spec.max_distance = number(args.get("--max-distance", "0"), "--max-distance");
  if (spec.max_distance != 0.0 && spec.kind != MethodKind::Sweep && spec.kind != MethodKind::Naive)
    throw Usage("--max-distance: the sweep and naive methods only");
  TimingPolicy policy;
  policy.min_reps = policy.max_reps = static_cast<int>(number(args.get("--reps", "3"), "--reps"));
  args.rejectUnused();
  const HeightField field = readHeightField(args.positional()[0]);
  const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
  const Measured m = measureMethod(context, field, spec, policy);
  const double pd = static_cast<double>(field.pixelCount()) * spec.directions;
  const int cores = std::max(1, context.device().compute_units);
  std::printf(
      "%s (%s) on %dx%d, K=%d, spu=%g: min %.4f s, median %.4f s over %zu runs; "
      "%.2f core-ns per pixel-direction on %s (%d compute units)\n",
      spec.name().c_str(), spec.outputs().c_str(), field.width, field.height, spec.directions,
      spec.samples_per_unit, m.timing.min(), m.timing.median(), m.timing.seconds.size(),
      m.timing.min() * cores / pd * 1e9, context.device().name.c_str(), cores);
  if (spec.kind != MethodKind::Sweep && spec.kind != MethodKind::Floor && spec.kind != MethodKind::Pyramid &&
      spec.max_distance == 0.0) {
    const MarchSteps steps =
        naiveMarchSteps(field, spec.directions, spec.samples_per_unit, baselineTileX(), baselineTileY(),
                        spec.kind == MethodKind::Radius ? spec.parameter * spec.samples_per_unit : 0);
    std::printf("  %.3g ray steps executed (%.3g inside the field): %.2f core-ns per executed step\n",
                steps.executed, steps.inside, m.timing.min() * cores / steps.executed * 1e9);
  }
  return 0;
}

int runVisibilityOne(Arguments& args) {
  if (args.positional().size() != 1) throw Usage("vis-run takes one height field");
  IntervisibilityOptions options;
  const std::string method = args.get("--method", "tree");
  if (method != "tree" && method != "naive") throw Usage("--method: tree or naive");
  options.method = method == "tree" ? IntervisibilityMethod::HullTree : IntervisibilityMethod::Naive;
  options.directions = static_cast<int>(number(args.get("-k", "16"), "-k"));
  const std::string tuning = args.get("--tuning", "default");
  const auto named = hullTreeTuningNamed(tuning);
  if (!named) throw Usage("--tuning: plain, deferred, default or zone");
  options.tree = *named;
  options.tree.safe_zone_steps = static_cast<int>(number(args.get("--zone-steps", "16"), "--zone-steps"));
  TimingPolicy policy;
  policy.min_reps = policy.max_reps = static_cast<int>(number(args.get("--reps", "3"), "--reps"));
  args.rejectUnused();
  const HeightField field = readHeightField(args.positional()[0]);
  const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
  IntervisibilityOutputs outputs;
  outputs.visible_count = true;
  const Timing t =
      timeWithWarmUp([&] { computeIntervisibility(context, crop(field, 64, 64), options, outputs); },
                     [&] { computeIntervisibility(context, field, options, outputs); }, policy);
  const double pd = static_cast<double>(field.pixelCount()) * options.directions;
  const int cores = std::max(1, context.device().compute_units);
  std::printf(
      "%s (%s) on %dx%d, K=%d: min %.4f s, median %.4f s over %zu runs; %.1f core-ns per pixel-direction\n",
      method.c_str(), method == "tree" ? tuning.c_str() : "-", field.width, field.height, options.directions,
      t.min(), t.median(), t.seconds.size(), t.min() * cores / pd * 1e9);
  if (method == "tree") {
    IntervisibilityOutputs stats;
    stats.statistics = true;
    const auto s = computeIntervisibility(context, field, options, stats).statistics;
    std::printf("  m_a %.3f, t_a %.3f, visible %.3f, walks skipped by the safe zone %.1f %%\n",
                s.meanHorizons(), s.meanIterations(), s.meanVisible(),
                s.receivers ? 100.0 * s.safe_zone_skips / s.receivers : 0.0);
  }
  return 0;
}

int checkTruth() {
  std::string summary;
  const auto failures = checkGroundTruth(&summary);
  for (const auto& f : failures) std::fprintf(stderr, "ground truth check failed: %s\n", f.c_str());
  std::printf("%s\n", summary.c_str());
  return failures.empty() ? 0 : 1;
}

}  // namespace

// "A,B,C" as its items (none for "").
std::vector<std::string> textList(const std::string& text) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find(',', at), text.size());
    out.push_back(text.substr(at, end - at));
    at = end + 1;
  }
  return out;
}

// "A,B,C" as whole numbers.
std::vector<int> intList(const std::string& text) {
  std::vector<int> out;
  for (const std::string& item : textList(text)) out.push_back(std::stoi(item));
  if (out.empty()) throw Usage("expected a list of whole numbers, got '" + text + "'");
  return out;
}

int viewshedAgreementCommand(Arguments& args) {
  const std::string at = args.get("--observer");
  const std::size_t comma = at.find(',');
  if (comma == std::string::npos) throw Usage("viewshed-agreement needs --observer COL,ROW");
  Observer o{static_cast<int>(number(at.substr(0, comma), "--observer")),
             static_cast<int>(number(at.substr(comma + 1), "--observer")),
             number(args.get("--observer-height", "2"), "--observer-height")};
  ViewshedOptions options;
  options.target_height = number(args.get("--target-height", "0"), "--target-height");
  const std::size_t samples = static_cast<std::size_t>(number(args.get("--samples", "20000"), "--samples"));
  const unsigned seed = static_cast<unsigned>(number(args.get("--seed", "1"), "--seed"));
  std::vector<std::string> paths = args.positional();
  args.rejectUnused();
  if (paths.size() < 2) throw Usage("viewshed-agreement needs DEM RASTER...");
  const HeightField field = readHeightField(paths[0]);
  validate(field, o);
  paths.erase(paths.begin());
  std::printf(
      "| raster | targets | visible (exact) | visible (raster) | Jaccard | disagreements | of them grazing "
      "|\n"
      "|---|---|---|---|---|---|---|\n");
  for (const auto& a : viewshedAgreement(field, o, options, paths, samples, seed))
    std::printf("| %s | %zu | %.2f %% | %.2f %% | %.4f | %zu | %zu |\n", a.raster.c_str(), a.targets,
                100.0 * a.reference_visible / std::max<std::size_t>(a.targets, 1),
                100.0 * a.raster_visible / std::max<std::size_t>(a.targets, 1), a.jaccard(),
                a.reference_visible + a.raster_visible - 2 * a.both, a.grazing);
  return 0;
}

int lightingTime(Arguments& args) {
  const EnvironmentMap map = readEnvironmentMap(args.get("--env"));
  const std::vector<int> ks = intList(args.get("-k", "16,64,256"));
  const int reps = std::stoi(args.get("--reps", "3"));
  const std::vector<std::string> fields = args.positional();
  args.rejectUnused();
  if (fields.empty()) throw Usage("lighting-time needs FIELD...");
  const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
  std::printf("| N | K | seconds per frame | ns per pixel and direction |\n|---|---|---|---|\n");
  for (const std::string& path : fields) {
    const HeightField field = readHeightField(path);
    timeEnvironmentLighting(context, field, map, 1, 1);  // the program built
    for (int k : ks) {
      const double s = timeEnvironmentLighting(context, field, map, k, reps);
      std::printf("| %d | %d | %.3f | %.1f |\n", field.width, k, s,
                  s * 1e9 / (double(field.pixelCount()) * k));
      std::fflush(stdout);
    }
  }
  std::printf("\n(%s, %s; the fastest of %d runs, the map %d x %d)\n", context.device().name.c_str(),
              context.device().platform.c_str(), reps, map.width, map.height);
  return 0;
}

int lightingError(Arguments& args) {
  EnvironmentMap map = readEnvironmentMap(args.get("--env"));
  const int samples = std::stoi(args.get("--samples", "4096"));
  const std::vector<int> ks = intList(args.get("-k", "4,8,16,32,64,128,256"));
  const std::vector<int> rows = intList(args.get("--rows", "8,16,32,64"));
  const std::vector<std::string> fields = args.positional();
  args.rejectUnused();
  if (fields.size() != 1) throw Usage("lighting-error needs one FIELD");
  const HeightField field = readHeightField(fields[0]);
  const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
  const auto start = std::chrono::steady_clock::now();
  const LightingReference ref = monteCarloIrradiance(field, map, samples);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::size_t values = ref.irradiance.size();
  double noise = 0.0;
  std::size_t lit = 0;
  for (std::size_t i = 0; i < values; ++i)
    if (ref.irradiance[i] > 0.0) noise += ref.noise[i] / ref.irradiance[i], ++lit;
  std::printf(
      "Reference: %d random directions per pixel, %d bright map pixels on grids, %.0f s on %d threads; "
      "its own noise (half the difference of its halves) %.3f %% on the mean.\n\n",
      ref.samples, ref.bright_pixels, seconds, threads(), 100.0 * noise / std::max<std::size_t>(lit, 1));
  auto errors = [&](int k, int table_rows) {
    map.table_rows = table_rows;
    HorizonOptions options;
    options.directions = k;
    HorizonOutputs outputs;
    outputs.environment = &map;
    const HorizonResult r = computeHorizons(context, field, options, outputs);
    // Relative errors where the reference receives light (a wholly hidden value has no scale).
    std::vector<double> e;
    double sum = 0.0;
    for (std::size_t i = 0; i < values; ++i) {
      if (!(ref.irradiance[i] > 0.0)) continue;
      e.push_back(std::fabs(r.irradiance[i] - ref.irradiance[i]) / ref.irradiance[i]);
      sum += e.back();
    }
    if (e.empty()) throw std::runtime_error("the reference receives no light anywhere");
    std::nth_element(e.begin(), e.begin() + e.size() * 99 / 100, e.end());
    return std::make_pair(sum / e.size(), e[e.size() * 99 / 100]);
  };
  std::printf("| K | bands | mean relative error | 99th percentile |\n|---|---|---|---|\n");
  for (int k : ks) {
    const auto [mean, worst] = errors(k, 0);
    std::printf("| %d | %d (the map's) | %.3f %% | %.2f %% |\n", k, map.height, 100.0 * mean, 100.0 * worst);
    std::fflush(stdout);
  }
  for (int table_rows : rows) {
    const auto [mean, worst] = errors(ks.back(), table_rows);
    std::printf("| %d | %d | %.3f %% | %.2f %% |\n", ks.back(), table_rows, 100.0 * mean, 100.0 * worst);
    std::fflush(stdout);
  }
  std::printf("\n(%s: %d x %d; the map %d x %d, %d channels; %s)\n", fields[0].c_str(), field.width,
              field.height, map.width, map.height, map.channels, context.device().name.c_str());
  return 0;
}

int main(int argc, char** argv) {
  try {
    if (argc < 2) throw Usage("no command given");
    const std::string command = argv[1];
    Arguments args(argc, argv, 2);
    if (command == "suite" || command == "visibility") {
      SuiteOptions options;
      options.mode = args.flag("--tiny") ? "tiny" : args.flag("--quick") ? "quick" : "full";
      options.out_dir = args.get("--out");
      options.data_dir = args.get("--data");
      options.dem_path = args.get("--dem");
      options.cache_dir = args.get("--cache", options.out_dir.empty() ? "" : options.out_dir + "/truth");
      options.commit = args.get("--commit", "unknown");
      options.self_path = std::filesystem::canonical("/proc/self/exe").string();
      if (command == "visibility") {
        for (const std::string& name : textList(args.get("--sections"))) {
          const auto& known = visibilitySections();
          if (std::find(known.begin(), known.end(), name) == known.end())
            throw Usage("--sections: unknown section '" + name + "' (time, stats, zone, scale, accuracy)");
          options.sections.push_back(name);
        }
        options.accuracy_contents = textList(args.get("--accuracy-contents"));
        const std::string ks = args.get("--accuracy-ks");
        if (!ks.empty()) options.accuracy_ks = intList(ks);
      }
      args.rejectUnused();
      if (options.out_dir.empty()) throw Usage("suite needs --out DIR");
      if (options.mode != "tiny" && (options.data_dir.empty() || options.dem_path.empty()))
        throw Usage("suite needs --data DIR and --dem FILE (bench/run_report.sh passes both)");
      const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
      return command == "suite" ? runSuite(context, options) : runVisibilitySuite(context, options);
    }
    if (command == "run") return runOne(args);
    if (command == "vis-run") return runVisibilityOne(args);
    if (command == "lighting-time") return lightingTime(args);
    if (command == "lighting-error") return lightingError(args);
    if (command == "viewshed-agreement") return viewshedAgreementCommand(args);
    if (command == "viewshed-culling") {
      const std::vector<int> levels = intList(args.get("--levels", "1,2,3,4"));
      const int reps = std::stoi(args.get("--reps", "3"));
      const std::vector<std::string> fields = args.positional();
      args.rejectUnused();
      if (fields.empty()) throw Usage("viewshed-culling needs FIELD...");
      for (int k : levels)
        if (k < 1 || k > 12) throw Usage("--levels: finest levels are 1 .. 12");
      const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
      for (const std::string& path : fields) viewshedCullingReport(context, path, levels, reps);
      return 0;
    }
    if (command == "pvs-scalar") {
      const int size = std::stoi(args.get("--size", "1024"));
      const std::string dem = args.get("--dem", "data/jacksboro_fault_dem.exr");
      const int rays = std::stoi(args.get("--rays", "1000000")), reps = std::stoi(args.get("--reps", "3"));
      const std::vector<std::string> fields = args.positional();
      args.rejectUnused();
      if (fields.empty()) throw Usage("pvs-scalar needs FIELD... (city, noise, dem)");
      if (size < 2 || rays < 1 || reps < 1)
        throw Usage("pvs-scalar: --size from 2, --rays and --reps from 1");
      pvsScalarReport(fields, size, dem, rays, reps);
      return 0;
    }
    if (command == "pvs-rays" || command == "pvs-recall") {
      const int size = std::stoi(args.get("--size", command == "pvs-rays" ? "1024" : "128"));
      const std::string dem = args.get("--dem", "data/jacksboro_fault_dem.exr");
      const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
      if (command == "pvs-rays") {
        const int rays = std::stoi(args.get("--rays", "1000000")), reps = std::stoi(args.get("--reps", "3"));
        const std::vector<std::string> fields = args.positional();
        args.rejectUnused();
        pvsRaysReport(context, fields, size, dem, rays, reps);
        return 0;
      }
      const int view_cell = std::stoi(args.get("--view-cell", "16")),
                tile = std::stoi(args.get("--tile", "8"));
      std::vector<std::uint64_t> samples;
      for (int n : intList(args.get("--samples", "10000,30000,100000,300000,1000000")))
        samples.push_back(std::uint64_t(n));
      const int check = std::stoi(args.get("--check-rays", "1000000"));
      std::vector<PvsMethod> methods;
      for (const std::string& m : textList(args.get("--methods", "agvs,sgvs,per-cell"))) {
        if (m != "agvs" && m != "sgvs" && m != "per-cell") throw Usage("--methods: agvs, sgvs, per-cell");
        methods.push_back(m == "agvs" ? PvsMethod::Agvs : m == "sgvs" ? PvsMethod::Sgvs : PvsMethod::PerCell);
      }
      const std::string reference = args.get("--reference", "yes");
      if (reference != "yes" && reference != "no") throw Usage("--reference: yes or no");
      std::vector<std::uint32_t> seeds;
      for (int s : intList(args.get("--seeds", "1"))) seeds.push_back(std::uint32_t(s));
      const int estimate_entries = std::stoi(args.get("--estimate-entries", "20"));
      if (estimate_entries < 0) throw Usage("--estimate-entries: 0 or more");
      const std::string inside = args.get("--inside", "no");
      if (inside != "yes" && inside != "no") throw Usage("--inside: yes or no");
      const std::vector<std::string> fields = args.positional();
      args.rejectUnused();
      pvsRecallReport(context, fields, size, dem, view_cell, tile, samples, check, methods,
                      reference == "yes", seeds, std::size_t(estimate_entries), inside == "yes");
      return 0;
    }
    if (command == "region") {
      const std::vector<std::string> sections = textList(args.get("--sections", "arealight,pair,error"));
      const int reps = std::stoi(args.get("--reps", "3"));
      const std::vector<std::string> fields = args.positional();
      args.rejectUnused();
      if (fields.empty()) throw Usage("region needs FIELD...");
      for (const std::string& section : sections)
        if (section != "arealight" && section != "arealight-quick" && section != "pair" &&
            section != "pair-quick" && section != "error" && section != "bitmask" &&
            section != "crossover")
          throw Usage(
              "--sections: arealight, arealight-quick, pair, pair-quick, error, bitmask, crossover (comma-separated)");
      const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
      for (const std::string& path : fields) regionVisibilityReport(context, path, sections, reps);
      return 0;
    }
    if (command == "field") {
      const std::vector<std::string> p = args.positional();
      args.rejectUnused();
      if (p.size() != 3) throw Usage("field needs NAME N OUT");
      const int n = std::stoi(p[1]);
      if (n < 1 || n > 16384) throw Usage("field: N is 1 .. 16384");
      const HeightField field = makeSyntheticField(p[0], n, n, 1);
      ImageChannels image;
      image.width = image.height = n;
      image.names = {"height"};
      image.planes = {field.heights};
      writeImage(p[2], image);
      return 0;
    }
    if (command == "inputs") {
      const std::string mode = args.flag("--quick") ? "quick" : "full";
      std::set<std::pair<std::string, int>> inputs;
      for (const auto& input : requiredInputs(mode)) inputs.insert(input);
      for (const auto& input : visibilityInputs(mode)) inputs.insert(input);
      for (const auto& [name, n] : inputs) std::printf("%s %d\n", name.c_str(), n);
      return 0;
    }
    if (command == "error-target") {
      SuiteOptions options;
      options.data_dir = args.get("--data", "data");
      options.dem_path = args.get("--dem", "data/jacksboro_fault_dem.exr");
      // The top-left N x N of the 256^2 contents (N <= 256), so that data/ holds every input.
      const int n = std::stoi(args.get("--size", "256"));
      if (n < 16 || n > 256) throw Usage("error-target: --size is 16 .. 256");
      std::vector<double> errors;
      for (const std::string& e : textList(args.get("--errors", "0.001,0.002,0.005,0.01,0.02,0.05")))
        errors.push_back(std::stod(e));
      const int reference = std::stoi(args.get("--reference-k", "2048"));
      const int reps = std::stoi(args.get("--reps", "3"));
      const int curve = std::stoi(args.get("--curve", "0"));
      const std::string output = args.get("--output", "svf-ao");
      if (output != "svf-ao" && output != "viewcount" && output != "horizon")
        throw Usage("error-target: --output is svf-ao, viewcount or horizon (--errors in degrees)");
      // (the refined runs' tiles beside the whole field's one K: svf-ao only)
      const std::string tile_text = args.get("--tile");
      if (output != "svf-ao" && !tile_text.empty())
        throw Usage("error-target: --tile refines svf-ao; the visible count takes one K");
      const int tile = tile_text.empty() ? 64 : std::stoi(tile_text);
      if (tile < kMinErrorTile)
        throw Usage("error-target: --tile is at least " + std::to_string(kMinErrorTile) + " pixels");
      const std::vector<std::string> names =
          textList(args.get("--contents", "fractal,bricks,sine,blocks,city_dsm,dem,mixed"));
      args.rejectUnused();
      std::vector<ErrorTargetField> fields;
      for (const std::string& name : names) {
        const auto content = [&](const std::string& which) {
          return crop(loadContent(options, which, 256).field, n, n);
        };
        if (name == "city_plain" || name == "town") {
          // An open plain beside a city: the city DSM with all but its left half (city_plain) or
          // its top-left quarter (town) levelled at its lowest height; the plain's pixels still see
          // the buildings.
          HeightField plain = content("city_dsm");
          const float ground = *std::min_element(plain.heights.begin(), plain.heights.end());
          for (int r = 0; r < plain.height; ++r)
            for (int c = 0; c < plain.width; ++c)
              if (c >= plain.width / 2 || (name == "town" && r >= plain.height / 2))
                plain.heights[static_cast<std::size_t>(r) * plain.width + c] = ground;
          fields.push_back({name, plain});
          continue;
        }
        if (name != "mixed") {
          fields.push_back({name, content(name)});
          continue;
        }
        // Open and dense parts in one field: the city DSM's left half beside the fractal terrain's
        // right half (heights times 40, the city's range).
        HeightField mixed = content("city_dsm");
        const HeightField terrain = content("fractal");
        for (int r = 0; r < mixed.height; ++r)
          for (int c = mixed.width / 2; c < mixed.width; ++c)
            mixed.heights[static_cast<std::size_t>(r) * mixed.width + c] = 40.0f * terrain.at(c, r);
        fields.push_back({"mixed", mixed});
      }
      if (output == "horizon") {
        const ComputeContext context = ComputeContext::create(ContextOptions::fromEnvironment());
        if (curve > 0)
          horizonErrorCurve(context, fields, reference, curve);
        else
          horizonTargetReport(context, fields, errors, reference, reps);
        return 0;
      }
      if (output == "viewcount") {
        viewcountTargetReport(ComputeContext::create(ContextOptions::fromEnvironment()), fields, errors,
                              reference, reps);
        return 0;
      }
      if (curve > 0) {
        errorCurve(ComputeContext::create(ContextOptions::fromEnvironment()), fields, reference, curve);
        return 0;
      }
      errorTargetReport(ComputeContext::create(ContextOptions::fromEnvironment()), fields, errors, reference,
                        reps, tile);
      return 0;
    }
    if (command == "check-truth") return checkTruth();
    if (command == "vectorize-report") {
      std::printf("%s", vectorizationRemarks(std::filesystem::canonical("/proc/self/exe").string()).c_str());
      return 0;
    }
    if (command == "vectorize-run") {
      const std::string which = args.positional().empty() ? "all" : args.positional()[0];
      return runKernelsOnce(ComputeContext::create(ContextOptions::fromEnvironment()), which);
    }
    if (command == "-h" || command == "--help") {
      std::printf("%s", kUsage);
      return 0;
    }
    throw Usage("unknown command '" + command + "'");
  } catch (const Usage& e) {
    std::fprintf(stderr, "hfvis_bench: %s\n%s", e.what(), kUsage);
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hfvis_bench: %s\n", e.what());
    return 1;
  }
}
