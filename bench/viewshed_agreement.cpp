// bench/viewshed_agreement.cpp: see viewshed_agreement.hpp.
#include "viewshed_agreement.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <thread>

#include "hfvis/image_io.hpp"
#include "hfvis_testing/viewshed_reference.hpp"

namespace hfvis::bench {

std::vector<ViewshedAgreement> viewshedAgreement(const HeightField& field, const Observer& o,
                                                 const ViewshedOptions& options, const std::vector<std::string>& rasters,
                                                 std::size_t samples, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> col(0, field.width - 1), row(0, field.height - 1);
  std::vector<std::pair<int, int>> targets(samples);
  for (auto& t : targets) t = {col(rng), row(rng)};
  // The exact test on the sample, on every core.
  struct Truth {
    bool in = false, visible = false, grazing = false;
  };
  std::vector<Truth> truth(samples);
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned w = 0; w < threads; ++w)
    pool.emplace_back([&, w] {
      for (std::size_t i = w; i < samples; i += threads) {
        const auto [c, r] = targets[i];
        if (!std::isfinite(field.at(c, r))) continue;
        const double gx = (c - o.col) * field.cell_size_x, gy = (r - o.row) * field.cell_size_y;
        if (options.max_distance > 0.0 && std::hypot(gx, gy) > options.max_distance) continue;
        truth[i].in = true;
        if (c == o.col && r == o.row) {
          truth[i].visible = true;
          continue;
        }
        truth[i].visible = referenceSightLine(field, o, options, c, r).visible;
        const Observer higher{o.col, o.row, o.height + 1e-4}, lower{o.col, o.row, o.height - 1e-4};
        truth[i].grazing = referenceSightLine(field, higher, options, c, r).visible !=
                           referenceSightLine(field, lower, options, c, r).visible;
      }
    });
  for (std::thread& t : pool) t.join();
  std::vector<ViewshedAgreement> out;
  for (const std::string& path : rasters) {
    const HeightField raster = readHeightField(path);
    if (raster.width != field.width || raster.height != field.height)
      throw std::runtime_error(path + " is " + std::to_string(raster.width) + "x" + std::to_string(raster.height) +
                               ", the DEM " + std::to_string(field.width) + "x" + std::to_string(field.height));
    ViewshedAgreement a;
    a.raster = path;
    for (std::size_t i = 0; i < samples; ++i) {
      const auto [c, r] = targets[i];
      const float v = raster.at(c, r);
      if (!truth[i].in || !std::isfinite(v)) continue;
      const bool seen = v > 0.0f;
      ++a.targets;
      a.reference_visible += truth[i].visible;
      a.raster_visible += seen;
      a.both += seen && truth[i].visible;
      a.grazing += seen != truth[i].visible && truth[i].grazing;
    }
    out.push_back(a);
  }
  return out;
}

}  // namespace hfvis::bench
