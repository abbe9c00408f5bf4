// bench/region_visibility.cpp: see region_visibility.hpp.
#include "region_visibility.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>

#include "hfvis/image_io.hpp"
#include "hfvis/region_visibility.hpp"
#include "metrics.hpp"

namespace hfvis::bench {
namespace {

double secondsOf(const std::function<void()>& body) {
  const auto start = std::chrono::steady_clock::now();
  body();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The fastest of `reps` runs of each body, the bodies interleaved round by round (the machine is
// shared: interleaving exposes each to the same load).
std::vector<double> fastestInterleaved(const std::vector<std::function<void()>>& bodies, int reps) {
  std::vector<double> best(bodies.size(), std::numeric_limits<double>::infinity());
  for (int r = 0; r < reps; ++r)
    for (std::size_t i = 0; i < bodies.size(); ++i) best[i] = std::min(best[i], secondsOf(bodies[i]));
  return best;
}

// `light` by each of `methods`, interleaved: their results and the fastest of `reps` times.
std::vector<double> timeMethods(const ComputeContext& context, const HeightField& f, const RegionSampling& light,
                                const std::vector<RegionVisibilityMethod>& methods, int reps,
                                std::vector<RegionVisibilityResult>& results) {
  results.assign(methods.size(), {});
  std::vector<std::function<void()>> bodies;
  for (std::size_t i = 0; i < methods.size(); ++i)
    bodies.push_back([&, i] {
      RegionVisibilityOptions o;
      o.method = methods[i];
      results[i] = computeRegionVisibility(context, f, light, o);
    });
  return fastestInterleaved(bodies, reps);
}

const char* name(RegionVisibilityMethod m) { return regionVisibilityMethodName(m); }

double highest(const HeightField& f) {
  double top = -std::numeric_limits<double>::infinity();
  for (float v : f.heights)
    if (std::isfinite(v)) top = std::max(top, double(v) * f.z_scale);
  return top;
}

// S grid points (whole columns and rows, so that every backend takes them, the viewsheds' too)
// spread over a side x side square centred on the field, at absolute height z: columns of
// ceil(sqrt(S)) points, the last row partly filled.
RegionSampling gridLight(const HeightField& f, int side, int samples, double z) {
  RegionSampling s;
  s.absolute = true;
  const int n = static_cast<int>(std::ceil(std::sqrt(double(samples))));
  const int c0 = f.width / 2 - side / 2, r0 = f.height / 2 - side / 2;
  for (int i = 0; i < samples; ++i)
    s.points.push_back({double(c0 + (i % n) * side / n), double(r0 + (i / n) * side / n), z});
  s.samples = samples;
  return s;
}

std::size_t differingBits(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += __builtin_popcount(a[i] ^ b[i]);
  return n;
}

// Area lights over every pixel: the viewsheds and the culled march at S = 32 and 128 (the
// viewsheds' cost grows linearly with S; the exact march, a full walk per pair, is left to the
// pairs), and the culled one at S = 256 against the light's size and height, with the viewsheds'
// time at that S projected from S = 32 and 128. One round each (a viewshed per sample is slow).
// (S = 1024 takes about four times S = 256's time in both: the culled march's work-items are
// words of 32 samples, each the same kind of work.)
// `quick`: only S = 32 in the interleaved table, then the culled march alone at S = 1024 (the
// target's S; the viewsheds' time there projected from S = 32), in minutes rather than an hour.
void arealightSection(const ComputeContext& context, const HeightField& f, bool quick) {
  const double top = highest(f);
  const double pixels = double(f.pixelCount());
  std::printf(
      "\n#### Area light over every pixel (light 64 x 64 px at the field's centre, %.1f above its "
      "highest point; sources on grid points, absolute)\n\n",
      20.0);
  std::printf(
      "| S | method | time (s) | Mrays/s | speed-up of culled | bits differing from culled |\n"
      "|---|---|---|---|---|---|\n");
  double viewshed_per_sample = 0.0;
  for (int samples : quick ? std::vector<int>{32} : std::vector<int>{32, 128}) {
    const RegionSampling light = gridLight(f, 64, samples, top + 20.0);
    const std::vector<RegionVisibilityMethod> methods = {RegionVisibilityMethod::Viewsheds,
                                                         RegionVisibilityMethod::Culled};
    std::vector<RegionVisibilityResult> results;
    const std::vector<double> t = timeMethods(context, f, light, methods, 1, results);
    viewshed_per_sample = std::max(viewshed_per_sample, t[0] / samples);
    for (std::size_t i = 0; i < methods.size(); ++i)
      std::printf("| %d | %s | %.3f | %.2f | %.1f | %zu of %.0f |\n", samples, name(methods[i]), t[i],
                  pixels * samples / t[i] * 1e-6, t[i] / t[1],
                  differingBits(results[i].bits, results[1].bits), pixels * samples);
  }
  std::printf(
      "\nThe viewsheds backend: %.3f s per sample (the larger of the S above), %.0f s projected at "
      "S = 1024.\n\n",
      viewshed_per_sample, viewshed_per_sample * 1024);
  std::printf(
      "| S | light side (px) | light above the highest point | culled time (s) | Mrays/s | "
      "projected speed-up over viewsheds | mean visible fraction |\n|---|---|---|---|---|---|---|\n");
  struct Case {
    int samples, side;
    double above;
  };
  const std::vector<Case> cases =
      quick ? std::vector<Case>{Case{1024, 64, 20.0}}
            : std::vector<Case>{Case{256, 64, 20.0}, Case{256, 16, 20.0}, Case{256, 64, 400.0}};
  for (const Case c : cases) {
    const RegionSampling light = gridLight(f, c.side, c.samples, top + c.above);
    RegionVisibilityResult r;
    RegionVisibilityOptions culled;
    culled.method = RegionVisibilityMethod::Culled;
    const double t = fastestInterleaved({[&] { r = computeRegionVisibility(context, f, light, culled); }}, 1)[0];
    double mean = 0.0;
    for (float v : r.fraction)
      if (std::isfinite(v)) mean += v;
    std::printf("| %d | %d | %.0f | %.2f | %.2f | %.1f | %.3f |\n", c.samples, c.side, c.above, t,
                pixels * c.samples / t * 1e-6, viewshed_per_sample * c.samples / t, mean / pixels);
  }
}

// The bitmask scatter against the culled march and the viewsheds, the light of arealightSection
// (64 x 64 px at the centre, 20 above the highest point, samples on grid points at one absolute
// height, so that all three take it): S = 32 (all three) and S = 1024 (culled and bitmask; the
// viewsheds' time projected from S = 32), interleaved, the fastest of `reps`; then the bits the
// bitmask's table leaves to the march against the table's size (S = 256). A table alone would
// call each of those bits either visible or hidden: the march finds `visible` of them visible,
// the rest hidden, so a table that called them hidden (the conservative outer polygons) gets
// the visible ones wrong, one that called them visible (the inner polygons) the hidden ones.
void bitmaskSection(const ComputeContext& context, const HeightField& f, int reps) {
  const double top = highest(f);
  const double pixels = double(f.pixelCount());
  std::printf(
      "\n#### The bitmask scatter (light 64 x 64 px at the field's centre, 20 above its highest point; "
      "sources on grid points, absolute; the fastest of %d, interleaved)\n\n"
      "| S | method | time (s) | Mrays/s | time / culled's | bits differing from culled | bits the "
      "march decided (bitmask) |\n|---|---|---|---|---|---|---|\n",
      reps);
  double viewshed_per_sample = 0.0;
  for (int samples : {32, 1024}) {
    const RegionSampling light = gridLight(f, 64, samples, top + 20.0);
    std::vector<RegionVisibilityMethod> methods = {RegionVisibilityMethod::Culled,
                                                   RegionVisibilityMethod::Bitmask};
    if (samples == 32) methods.push_back(RegionVisibilityMethod::Viewsheds);
    std::vector<RegionVisibilityResult> results;
    const std::vector<double> t = timeMethods(context, f, light, methods, reps, results);
    if (samples == 32) viewshed_per_sample = t[2] / samples;
    for (std::size_t i = 0; i < methods.size(); ++i)
      std::printf(
          "| %d | %s | %.3f | %.2f | %.2f | %zu of %.0f | %s |\n", samples, name(methods[i]), t[i],
          pixels * samples / t[i] * 1e-6, t[i] / t[0], differingBits(results[i].bits, results[0].bits),
          pixels * samples,
          methods[i] == RegionVisibilityMethod::Bitmask
              ? (std::to_string(results[i].exact_tested) + " (" +
                 std::to_string(100.0 * results[i].exact_tested / (pixels * samples)).substr(0, 5) + " %)")
                    .c_str()
              : "");
    if (samples == 1024)
      std::printf("| 1024 | viewsheds (projected from S = 32) | %.1f | | %.2f | | |\n",
                  viewshed_per_sample * 1024, viewshed_per_sample * 1024 / t[0]);
  }
  std::printf(
      "\n| table (angles = offsets) | S | time (s) | bits the march decided | of them visible (a "
      "hidden-calling table's errors) | hidden (a visible-calling table's errors) | bits differing from "
      "culled |\n|---|---|---|---|---|---|---|\n");
  const RegionSampling light = gridLight(f, 64, 256, top + 20.0);
  RegionVisibilityOptions culled;
  culled.method = RegionVisibilityMethod::Culled;
  const RegionVisibilityResult want = computeRegionVisibility(context, f, light, culled);
  for (int size : {16, 64, 256}) {
    RegionVisibilityOptions o;
    o.method = RegionVisibilityMethod::Bitmask;
    o.bitmask_table = size;
    RegionVisibilityResult r;
    const double t = fastestInterleaved({[&] { r = computeRegionVisibility(context, f, light, o); }}, 1)[0];
    std::printf("| %d | 256 | %.3f | %llu (%.2f %%) | %llu | %llu | %zu |\n", size, t,
                (unsigned long long)r.exact_tested, 100.0 * r.exact_tested / (pixels * 256),
                (unsigned long long)r.exact_tested_visible,
                (unsigned long long)(r.exact_tested - r.exact_tested_visible),
                differingBits(r.bits, want.bits));
  }
}

// Which method the default (RegionVisibilityMethod::Auto) should take for an area light over
// every pixel: the culled march against the bitmask scatter, interleaved (the fastest of `reps`),
// against S and against the light's size and height above the highest point (Eisemann &
// Decoret's variables), with the method Auto takes (bitmask from kBitmaskFromSamples samples of such
// a light on). The bits are the same (both exact).
void crossoverSection(const ComputeContext& context, const HeightField& f, int reps) {
  const double top = highest(f);
  std::printf(
      "\n#### Culled or bitmask: the default's choice (area light at the field's centre, sources on grid "
      "points, absolute; the fastest of %d, interleaved)\n\n"
      "| light side (px) | above the highest point | S | culled (s) | bitmask (s) | bitmask / culled | auto "
      "takes |\n|---|---|---|---|---|---|---|\n",
      reps);
  struct Case {
    int side;
    double above;
    int samples;
  };
  std::vector<Case> cases;
  for (int samples : {32, 48, 64, 128, 256}) cases.push_back({64, 20.0, samples});
  for (int samples : {32, 64, 256}) cases.push_back({16, 20.0, samples});
  for (int samples : {32, 64, 256}) cases.push_back({64, 400.0, samples});
  for (const Case c : cases) {
    const RegionSampling light = gridLight(f, c.side, c.samples, top + c.above);
    RegionVisibilityResult culled, bitmask;
    RegionVisibilityOptions oc, ob;
    oc.method = RegionVisibilityMethod::Culled;
    ob.method = RegionVisibilityMethod::Bitmask;
    const std::vector<double> t = fastestInterleaved(
        {[&] { culled = computeRegionVisibility(context, f, light, oc); },
         [&] { bitmask = computeRegionVisibility(context, f, light, ob); }},
        reps);
    if (bitmask.bits != culled.bits) std::printf("(bits differ: a defect)\n");
    std::printf("| %d | %.0f | %d | %.3f | %.3f | %.2f | %s |\n", c.side, c.above, c.samples, t[0], t[1],
                t[1] / t[0], c.samples >= kBitmaskFromSamples ? "bitmask" : "culled");
  }
}

// Region pairs: two squares of `side` pixels (32 x 32 samples each, 2 above the surface), their
// centres `distance` apart along a row through the field's centre, by the one-shot library call
// (the field prepared every call) and by the call on a field prepared once (RegionField, as a
// renderer or a loop over sites calls it; its preparation timed apart), interleaved.
// `quick`: the culled method alone (exact's column 0), for profiling.
void pairSection(const ComputeContext& context, const HeightField& f, int reps, bool quick) {
  // (the preparation's wall and CPU time: the fastest of `reps`)
  double prepare_cpu = std::numeric_limits<double>::infinity();
  std::unique_ptr<RegionField> prepared;
  const double prepare = fastestInterleaved({[&] {
                                              const double start = processCpuSeconds();
                                              prepared = std::make_unique<RegionField>(context, f);
                                              prepare_cpu =
                                                  std::min(prepare_cpu, processCpuSeconds() - start);
                                            }},
                                            reps)[0];
  std::printf(
      "\n#### Region pairs (32 x 32 samples each, 2 above the surface, the squares' centres on one row)"
      "\n\nculled: the one-shot call (computeRegionPairVisibility on the HeightField: the field prepared "
      "every call); prepared: the call on a RegionField prepared once before the rows (%.1f ms, CPU %.1f "
      "ms, not in the rows); the three calls interleaved, the fastest of %d; CPU: every thread's, the "
      "fewest of the runs.\n\n| side (px) | distance (px) | exact (ms) | culled (ms) | culled CPU (ms) | "
      "culled Mrays/s | speed-up | visible fraction | bits differing | prepared (ms) | prepared CPU (ms) "
      "| prepared speed-up | prepared bits differing |\n|---|---|---|---|---|---|---|---|---|---|---|---|"
      "---|\n",
      prepare * 1e3, prepare_cpu * 1e3, reps);
  struct Case {
    int side, distance;
  };
  for (const Case c : {Case{32, 64}, Case{32, 256}, Case{32, 768}, Case{8, 256}, Case{128, 256}}) {
    RegionSampling a, b;
    a.samples = b.samples = 1024;
    a.height = b.height = 2.0;
    const int row = f.height / 2 - c.side / 2, left = f.width / 2 - c.distance / 2 - c.side / 2;
    a.rectangle = {left, row, left + c.side - 1, row + c.side - 1};
    b.rectangle = {left + c.distance, row, left + c.distance + c.side - 1, row + c.side - 1};
    RegionPairVisibilityResult exact, culled, on_prepared;
    RegionVisibilityOptions oe, oc;
    oe.method = RegionVisibilityMethod::Exact;
    oc.method = RegionVisibilityMethod::Culled;
    // (the culled calls' CPU time: the fewest seconds of their runs, all threads)
    double culled_cpu = std::numeric_limits<double>::infinity(), prepared_cpu = culled_cpu;
    std::vector<std::function<void()>> bodies = {
        [&] { exact = computeRegionPairVisibility(context, f, a, b, oe); },
        [&] {
          const double start = processCpuSeconds();
          culled = computeRegionPairVisibility(context, f, a, b, oc);
          culled_cpu = std::min(culled_cpu, processCpuSeconds() - start);
        },
        [&] {
          const double start = processCpuSeconds();
          on_prepared = computeRegionPairVisibility(*prepared, a, b, oc);
          prepared_cpu = std::min(prepared_cpu, processCpuSeconds() - start);
        }};
    if (quick) bodies[0] = [&] { exact = culled; };
    const std::vector<double> t = fastestInterleaved(bodies, reps);
    std::printf("| %d | %d | %.1f | %.1f | %.1f | %.1f | %.1f | %.3f | %zu | %.1f | %.1f | %.1f | %zu |\n",
                c.side, c.distance, t[0] * 1e3, t[1] * 1e3, culled_cpu * 1e3, 1024.0 * 1024.0 / t[1] * 1e-6,
                t[0] / t[1], double(culled.clear_pairs) / double(culled.pairs),
                differingBits(exact.bits, culled.bits), t[2] * 1e3, prepared_cpu * 1e3, t[0] / t[2],
                differingBits(exact.bits, on_prepared.bits));
  }
  // The call's cost outside the marches: one sample each side.
  RegionSampling a, b;
  a.samples = b.samples = 1;
  a.rectangle = {f.width / 2 - 40, f.height / 2, f.width / 2 - 40, f.height / 2};
  b.rectangle = {f.width / 2 + 40, f.height / 2, f.width / 2 + 40, f.height / 2};
  double fixed_cpu = std::numeric_limits<double>::infinity(), fixed_prepared_cpu = fixed_cpu;
  const std::vector<double> fixed = fastestInterleaved(
      {[&] {
         const double start = processCpuSeconds();
         computeRegionPairVisibility(context, f, a, b, {});
         fixed_cpu = std::min(fixed_cpu, processCpuSeconds() - start);
       },
       [&] {
         const double start = processCpuSeconds();
         computeRegionPairVisibility(*prepared, a, b, {});
         fixed_prepared_cpu = std::min(fixed_prepared_cpu, processCpuSeconds() - start);
       }},
      reps);
  std::printf(
      "\nA 1 x 1 pair (the call's fixed cost: the field's upload, the pyramid): %.1f ms (CPU %.1f ms); on "
      "the prepared field: %.1f ms (CPU %.1f ms).\n",
      fixed[0] * 1e3, fixed_cpu * 1e3, fixed[1] * 1e3, fixed_prepared_cpu * 1e3);
}

// The visible fraction at S = 1024 (and 256) against a reference of 16384 samples (four seeds of
// 4096, averaged) under a jittered 32 x 32 light 20 above the highest point, on the field's
// central 128 x 128 pixels.
void errorSection(const ComputeContext& context, const HeightField& full, int) {
  const int n = std::min({128, full.width, full.height});
  HeightField f = full;
  f.width = f.height = n;
  f.heights.assign(std::size_t(n) * n, 0.0f);
  const int c0 = full.width / 2 - n / 2, r0 = full.height / 2 - n / 2;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) f.heights[std::size_t(r) * n + c] = full.at(c0 + c, r0 + r);
  f.georeference = {};
  RegionSampling light;
  light.absolute = true;
  light.height = highest(f) + 20.0;
  light.rectangle = {n / 2 - 16, n / 2 - 16, n / 2 + 15, n / 2 + 15};
  std::vector<double> reference(f.pixelCount(), 0.0);
  for (std::uint32_t seed = 101; seed <= 104; ++seed) {
    light.samples = kMaxRegionSamples;
    RegionVisibilityOptions o;
    o.method = RegionVisibilityMethod::Culled;
    o.seed = seed;
    const RegionVisibilityResult r = computeRegionVisibility(context, f, light, o);
    for (std::size_t p = 0; p < f.pixelCount(); ++p) reference[p] += r.fraction[p] / 4.0;
  }
  std::printf(
      "\n#### The visible fraction against a Monte-Carlo reference (%d x %d pixels of the field's centre,"
      " a 32 x 32 px light 20 above the highest point, jittered; the reference: 4 x 4096 samples)\n\n"
      "| S | decorrelated | mean absolute error | largest error | penumbra pixels (0 < reference < 1) | "
      "their mean absolute error |\n|---|---|---|---|---|---|\n",
      n, n);
  for (int samples : {256, 1024})
    for (bool decorrelate : {false, true}) {
      light.samples = samples;
      RegionVisibilityOptions o;
      o.method = RegionVisibilityMethod::Culled;
      o.decorrelate = decorrelate;
      const RegionVisibilityResult r = computeRegionVisibility(context, f, light, o);
      double sum = 0.0, worst = 0.0, penumbra_sum = 0.0;
      std::size_t penumbra = 0;
      for (std::size_t p = 0; p < f.pixelCount(); ++p) {
        const double e = std::fabs(r.fraction[p] - reference[p]);
        sum += e, worst = std::max(worst, e);
        if (reference[p] > 0.0 && reference[p] < 1.0) penumbra_sum += e, ++penumbra;
      }
      std::printf("| %d | %s | %.4f | %.4f | %zu | %.4f |\n", samples, decorrelate ? "yes" : "no",
                  sum / f.pixelCount(), worst, penumbra, penumbra ? penumbra_sum / penumbra : 0.0);
    }
}

}  // namespace

void regionVisibilityReport(const ComputeContext& context, const std::string& path,
                            const std::vector<std::string>& sections, int reps) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // each row as it is measured (long sections)
  const HeightField field = readHeightField(path);
  std::printf("\n### %s (%d x %d)\n", path.c_str(), field.width, field.height);
  for (const std::string& s : sections) {
    if (s == "arealight" || s == "arealight-quick") arealightSection(context, field, s == "arealight-quick");
    if (s == "pair" || s == "pair-quick") pairSection(context, field, reps, s == "pair-quick");
    if (s == "error") errorSection(context, field, reps);
    if (s == "bitmask") bitmaskSection(context, field, reps);
    if (s == "crossover") crossoverSection(context, field, reps);
    std::fflush(stdout);
  }
}

}  // namespace hfvis::bench
