// bench/viewshed_culling.cpp: see viewshed_culling.hpp.
#include "viewshed_culling.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "hfvis/image_io.hpp"

namespace hfvis::bench {

ViewshedPyramid trimmedPyramid(const ViewshedPyramid& pyramid, int k) {
  ViewshedPyramid out = pyramid;
  while (out.levels.size() > 1 && out.levels.front().k < k) {
    const ViewshedPyramid::Level& fine = out.levels.front();
    const ViewshedPyramid::Level& coarse = out.levels[1];
    std::vector<std::uint32_t> valid(static_cast<std::size_t>(coarse.nodes_x) * coarse.nodes_y, 0);
    for (int y = 0; y < fine.nodes_y; ++y)
      for (int x = 0; x < fine.nodes_x; ++x)
        valid[static_cast<std::size_t>(y / 2) * coarse.nodes_x + x / 2] += out.valid_points[static_cast<std::size_t>(y) * fine.nodes_x + x];
    out.valid_points = std::move(valid);
    out.levels.erase(out.levels.begin());
  }
  out.finest_level = out.levels.front().k;
  return out;
}

namespace {

double secondsOf(const std::function<void()>& body) {
  const auto start = std::chrono::steady_clock::now();
  body();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Observer extreme(const HeightField& f, bool lowest, double eye) {
  std::size_t best = 0;
  for (std::size_t p = 0; p < f.heights.size(); ++p) {
    const float v = f.heights[p];
    if (!std::isfinite(v)) continue;
    if (!std::isfinite(f.heights[best]) || (lowest ? v < f.heights[best] : v > f.heights[best])) best = p;
  }
  return {static_cast<int>(best % f.width), static_cast<int>(best / f.width), eye};
}

}  // namespace

void viewshedCullingReport(const ComputeContext& context, const std::string& path, const std::vector<int>& levels,
                           int reps) {
  const HeightField field = readHeightField(path);
  ViewshedPyramidOptions options;
  options.finest_level = *std::min_element(levels.begin(), levels.end());
  const ViewshedPyramid full = buildViewshedPyramid(context, field, options);
  std::printf("\n### %s (%d x %d)\n\n", path.c_str(), field.width, field.height);
  std::printf("Preprocessing (%d sectors x %d directions, one build at finest level %d): %.2f s.\n\n", full.sectors,
              full.directions / full.sectors, options.finest_level, full.build_seconds);
  std::printf("| finest level kept | node | levels | memory (MiB) |\n|---|---|---|---|\n");
  std::vector<ViewshedPyramid> pyramids;
  for (int k : levels) {
    pyramids.push_back(trimmedPyramid(full, k));
    const ViewshedPyramid& p = pyramids.back();
    std::printf("| %d | %d x %d | %d .. %d | %.2f |\n", k, 1 << k, 1 << k, p.levels.front().k, p.levels.back().k,
                p.bytes() / (1024.0 * 1024.0));
  }
  const struct {
    const char* name;
    Observer o;
  } observers[] = {{"valley (lowest point, eye 2)", extreme(field, true, 2.0)},
                   {"ground level (centre, eye 2)", {field.width / 2, field.height / 2, 2.0}},
                   {"high (centre, eye 100)", {field.width / 2, field.height / 2, 100.0}}};
  std::printf("\n| observer | finest level | hidden | culled (of the points) | culled (of the hidden) | exact (s) | culled (s) | "
              "speed-up |\n|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, o] : observers) {
    ViewshedResult exact;
    // Warm: the program built (PoCL compiles each kernel at its first launch), the buffers touched.
    ViewshedOptions warm;
    warm.pyramid = &pyramids.front();
    computeViewshed(context, field, o, warm);
    computeViewshed(context, field, o, {});
    for (std::size_t i = 0; i < levels.size(); ++i) {
      ViewshedOptions culled;
      culled.pyramid = &pyramids[i];
      ViewshedResult r;
      double t_exact = std::numeric_limits<double>::infinity(), t_culled = t_exact;
      for (int rep = 0; rep < reps; ++rep) {  // interleaved
        t_exact = std::min(t_exact, secondsOf([&] { exact = computeViewshed(context, field, o, {}); }));
        t_culled = std::min(t_culled, secondsOf([&] { r = computeViewshed(context, field, o, culled); }));
      }
      std::size_t hidden = 0, points = 0, differ = 0;
      for (std::size_t p = 0; p < exact.visible.size(); ++p) {
        points += !std::isnan(exact.visible[p]);
        hidden += exact.visible[p] == 0.0f;
        differ += !(exact.visible[p] == r.visible[p] || (std::isnan(exact.visible[p]) && std::isnan(r.visible[p])));
      }
      if (differ) std::printf("| %s | %d | CULLED DIFFERS FROM EXACT at %zu points | | | | | |\n", name, levels[i], differ);
      std::printf("| %s (%d,%d) | %d | %.1f %% | %.1f %% | %.1f %% | %.3f | %.3f | %.2f |\n", name, o.col, o.row, levels[i],
                  100.0 * hidden / std::max<std::size_t>(points, 1), 100.0 * r.culled / std::max<std::size_t>(points, 1),
                  100.0 * r.culled / std::max<std::size_t>(hidden, 1), t_exact, t_culled, t_exact / t_culled);
    }
  }
}

}  // namespace hfvis::bench
