// bench/pvs_bench.cpp: see pvs_bench.hpp.
#include "pvs_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <random>
#include <stdexcept>

#include "hfvis/image_io.hpp"
#include "hfvis/pvs.hpp"
#include "hfvis_testing/pvs_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "ops/pvs_ray.hpp"

namespace hfvis::bench {
namespace {

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

const char* methodName(PvsMethod m) {
  return m == PvsMethod::Agvs ? "AGVS" : m == PvsMethod::Sgvs ? "SGVS" : "per-cell (REF)";
}

}  // namespace

HeightField pvsBenchField(const std::string& name, int size, const std::string& dem_path) {
  if (name != "dem") {
    HeightField f = makeSyntheticField(name, size, size, 7);
    return f;
  }
  const HeightField dem = readHeightField(dem_path);
  if (dem.width < size || dem.height < size)
    throw std::runtime_error("the DEM is smaller than " + std::to_string(size) + " x " +
                             std::to_string(size));
  HeightField f = dem;
  f.width = f.height = size;
  f.heights.resize(std::size_t(size) * size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) f.heights[std::size_t(y) * size + x] = dem.at(x, y);
  f.georeference = {};
  return f;
}

void pvsRaysReport(const ComputeContext& context, const std::vector<std::string>& fields, int size,
                   const std::string& dem_path, int rays, int reps) {
  std::printf(
      "| field | rays | hits | rays/s (hit only) | rays/s (with view cells) | rays per CPU second (hit only) "
      "| "
      "(with view cells) | rays/s, whole calls (hit only) |\n"
      "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
  for (const std::string& name : fields) {
    const HeightField f = pvsBenchField(name, size, dem_path);
    RayCastOptions plain;
    const std::vector<HeightRay> in = randomViewRays(f, plain.grid, rays, 5);
    // Wall time, and the process's CPU time (host and PoCL's threads), which a machine shared
    // with other work inflates less.
    double best_plain = 1e30, best_listed = 1e30, cpu_plain = 1e30, cpu_listed = 1e30, best_call = 1e30;
    std::size_t hits = 0;
    // The caster as the samplers use it: the field uploaded and its pyramid built once, then
    // batch after batch.
    detail::withRayCaster(context, f, plain.grid, 0.0, 0, [&](detail::RayCaster& caster) {
      // Warm-up: two full launches each way, so that the launches' buffers are allocated (and
      // their pages touched) before the timing, as they are after a sampler's first batch.
      const std::vector<HeightRay> warm(in.begin(), in.begin() + std::min<std::size_t>(in.size(), 1 << 17));
      caster.cast(warm, true);
      caster.cast(warm, false);
      for (int r = 0; r < reps; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        std::clock_t c0 = std::clock();
        const detail::RayCasts a = caster.cast(in, false);
        best_plain = std::min(best_plain, seconds(t0));
        cpu_plain = std::min(cpu_plain, double(std::clock() - c0) / CLOCKS_PER_SEC);
        t0 = std::chrono::steady_clock::now();
        c0 = std::clock();
        caster.cast(in, true);
        best_listed = std::min(best_listed, seconds(t0));
        cpu_listed = std::min(cpu_listed, double(std::clock() - c0) / CLOCKS_PER_SEC);
        hits = std::size_t(std::count_if(a.cell.begin(), a.cell.end(), [](int c) { return c >= 0; }));
      }
    });
    // One whole call each: upload, pyramid and cast (what castHeightFieldRays costs once).
    for (int r = 0; r < reps; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      castHeightFieldRays(context, f, in, plain);
      best_call = std::min(best_call, seconds(t0));
    }
    std::printf("| %s %dx%d | %d | %.1f %% | %.2fM | %.2fM | %.2fM | %.2fM | %.2fM |\n", name.c_str(),
                f.width, f.height, rays, 100.0 * double(hits) / rays, rays / best_plain / 1e6,
                rays / best_listed / 1e6, rays / cpu_plain / 1e6, rays / cpu_listed / 1e6,
                rays / best_call / 1e6);
    std::fflush(stdout);
  }
  std::printf(
      "\n(view-band rays at 1.7 above the surface in uniform directions, unbounded; the fastest of %d "
      "casts on one caster (the field uploaded and its pyramid built once, as the samplers cast), and "
      "of %d whole castHeightFieldRays calls, each with its upload and pyramid; %s)\n",
      reps, reps, context.device().name.c_str());
}

void pvsScalarReport(const std::vector<std::string>& fields, int size, const std::string& dem_path, int rays,
                     int reps) {
  std::printf(
      "| field | rays | us per ray (hit only) | us per ray (with view cells) | checksum (hit only) | (with "
      "view "
      "cells) |\n| --- | ---: | ---: | ---: | --- | --- |\n");
  auto thread_seconds = [] {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
  };
  for (const std::string& name : fields) {
    const HeightField f = pvsBenchField(name, size, dem_path);
    const PvsGrid grid;
    const PvsLayout l = pvsLayout(f, grid);
    std::vector<HeightRay> in = randomViewRays(f, grid, rays, 5);
    // The caster's order (src/ops/pvs.cpp, originOrder): by the 16 x 16-cell block holding the
    // origin, clamped into the field, blocks row by row, stable.
    auto block = [&](const HeightRay& r) {
      const float x = std::clamp(r.ox, 0.0f, float(l.cells_x - 1)),
                  y = std::clamp(r.oy, 0.0f, float(l.cells_y - 1));
      return (int(y) >> 4) * ((l.cells_x >> 4) + 1) + (int(x) >> 4);
    };
    std::stable_sort(in.begin(), in.end(),
                     [&](const HeightRay& a, const HeightRay& b) { return block(a) < block(b); });
    const std::vector<float> h = detail::rayHeights(f);
    const detail::RayPyramid p = detail::buildRayPyramid(h, f.width, f.height);
    const int cap = l.view_x + l.view_y;
    std::vector<int> pierced(std::size_t(cap) + 1);
    std::vector<float> pierced_t(std::size_t(cap) + 1);
    double best[2] = {1e30, 1e30};
    unsigned long long sums[2] = {0, 0};
    for (int r = 0; r < reps; ++r)
      for (int lists = 0; lists < 2; ++lists) {
        // FNV-1a over the results' words.
        unsigned long long sum = 1469598103934665603ull;
        auto mix = [&](std::uint32_t v) { sum = (sum ^ v) * 1099511628211ull; };
        auto bits = [](float v) {
          std::uint32_t b;
          std::memcpy(&b, &v, sizeof b);
          return b;
        };
        const double t0 = thread_seconds();
        for (const HeightRay& ray : in) {
          int count = 0, cell = -1;
          const float t = detail::hf_ray_cast(
              h.data(), f.width, f.height, p.values.data(), p.levels.data(), p.top, ray.ox, ray.oy, ray.oz,
              ray.dx, ray.dy, ray.dz, ray.t_max, 0.0f, float(f.cell_size_x), float(f.cell_size_y),
              grid.view_cell, l.view_x, float(grid.band_low), float(grid.band_high), lists ? cap : 0,
              pierced.data(), pierced_t.data(), 1, &count, &cell);
          mix(bits(t));
          mix(std::uint32_t(cell));
          mix(std::uint32_t(count));
          for (int j = 0; j < count; ++j) mix(std::uint32_t(pierced[j])), mix(bits(pierced_t[j]));
        }
        best[lists] = std::min(best[lists], thread_seconds() - t0);
        sums[lists] = sum;
      }
    std::printf("| %s %dx%d | %d | %.3f | %.3f | %016llx | %016llx |\n", name.c_str(), f.width, f.height,
                rays, 1e6 * best[0] / rays, 1e6 * best[1] / rays, sums[0], sums[1]);
    std::fflush(stdout);
  }
  std::printf(
      "\n(kernels/shared/heightfield_ray.cl compiled as C++, one core; view-band rays as pvs-rays casts, in "
      "the "
      "caster's order; the fastest of %d; thread CPU time)\n",
      reps);
}

void pvsRecallReport(const ComputeContext& context, const std::vector<std::string>& fields, int size,
                     const std::string& dem_path, int view_cell, int tile,
                     const std::vector<std::uint64_t>& samples, int check_rays,
                     const std::vector<PvsMethod>& methods, bool reference,
                     const std::vector<std::uint32_t>& seeds, std::size_t estimate_entries, bool inside) {
  PvsGrid grid;
  grid.view_cell = view_cell;
  grid.tile = tile;
  for (const std::string& name : fields) {
    const HeightField f = pvsBenchField(name, size, dem_path);
    auto t0 = std::chrono::steady_clock::now();
    const PvsResult dense = reference ? computeDensePvs(context, f, grid) : PvsResult{};
    const double dense_seconds = seconds(t0);
    const PvsResult dense_inside =
        reference && inside ? computeDensePvs(context, f, grid, DenseTargets::InsideTiles) : PvsResult{};
    const std::vector<HeightRay> check = randomViewRays(f, grid, check_rays, 99);
    const RayCastResult check_hits = castHeightFieldRays(context, f, check);
    std::printf("\n### %s %d x %d (view cells %d x %d cells, tiles %d x %d)\n\n", name.c_str(), f.width,
                f.height, view_cell, view_cell, tile, tile);
    if (reference)
      std::printf("Dense reference: %zu of %d entries (%.1f %%), %.1f s.\n\n", dense.entries(),
                  dense.layout.viewCells() * dense.layout.tiles(),
                  100.0 * double(dense.entries()) / (dense.layout.viewCells() * dense.layout.tiles()),
                  dense_seconds);
    if (reference && inside)
      std::printf(
          "Inside the tiles (their grid points off the tiles' borders): %zu entries; %zu of the "
          "reference's are seen only at a tile's border.\n\n",
          dense_inside.entries(), dense.entries() - dense_inside.entries());
    if (!reference) std::printf("(no dense reference: recall not measured)\n\n");
    std::printf(
        "| sampler | samples | settling the estimate | rays | recall | recall inside the tiles | "
        "estimated pixel error | its rays: found once / uniform | measured pixel error | its rays: wrong | "
        "seconds |\n"
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    PvsResult last_agvs;
    int runs = 0, within = 0;
    for (PvsMethod method : methods) {
      for (std::uint64_t n : samples)
        for (std::uint32_t seed : seeds) {
          PvsOptions options;
          options.method = method;
          options.samples = n;
          options.seed = seed;
          options.estimate_entries = estimate_entries;
          const PvsResult pvs = computePvs(context, f, grid, options);
          const std::string recall = reference ? std::to_string(pvsRecall(pvs, dense)).substr(0, 6) : "-";
          const std::string recall_inside =
              reference && inside ? std::to_string(pvsRecall(pvs, dense_inside)).substr(0, 6) : "-";
          const double measured = measuredPixelError(f, pvs, check, check_hits, options.resolution);
          const std::string sampler = std::string(methodName(method)) +
                                      (seeds.size() > 1 ? " (seed " + std::to_string(seed) + ")" : "");
          ++runs;
          within += pvs.pixel_error >= 0.5 * measured && pvs.pixel_error <= 2.0 * measured;
          std::printf("| %s | %llu | %llu | %llu | %s | %s | %.1f | %.0f / %llu | %.1f | %.0f | %.2f |\n",
                      sampler.c_str(), static_cast<unsigned long long>(n),
                      static_cast<unsigned long long>(pvs.estimate_samples),
                      static_cast<unsigned long long>(pvs.rays), recall.c_str(), recall_inside.c_str(),
                      pvs.pixel_error, pvs.pixel_error * double(pvs.uniform_rays) / options.resolution,
                      static_cast<unsigned long long>(pvs.uniform_rays), measured,
                      measured * double(check.size()) / options.resolution, pvs.seconds);
          std::fflush(stdout);
          if (method == PvsMethod::Agvs) last_agvs = pvs;
        }
    }
    std::printf("\nThe estimate within a factor 2 of the measured pixel error at the end of %d of these %d runs.\n",
                within, runs);
    if (last_agvs.history.empty()) continue;
    std::printf("\nAGVS's mixture over its %llu-sample run (per batch of 65536 samples):\n\n| samples |",
                static_cast<unsigned long long>(samples.back()));
    for (int d = 0; d < kPvsDistributions; ++d) std::printf(" %s |", pvsDistributionName(d));
    std::printf("\n| ---: |");
    for (int d = 0; d < kPvsDistributions; ++d) std::printf(" ---: |");
    std::printf("\n");
    for (const PvsProgress& p : last_agvs.history) {
      std::printf("| %llu |", static_cast<unsigned long long>(p.samples));
      // (a batch settling the estimate draws view-direction samples alone)
      for (int d = 0; d < kPvsDistributions; ++d)
        std::printf(" %.3f |", p.settling ? (d == 0 ? 1.0 : 0.0) : p.probability[d]);
      std::printf(p.settling ? " settling |\n" : "\n");
    }
  }
  std::printf("\n(pixel errors per million rays; measured with %d random view rays; %s)\n", check_rays,
              context.device().name.c_str());
}

}  // namespace hfvis::bench
