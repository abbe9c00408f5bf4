// pvs_reference.cpp: see hfvis_testing/pvs_reference.hpp.
#include "hfvis_testing/pvs_reference.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "ops/pvs_ray.hpp"

namespace hfvis {

RayCastResult referenceCastHeightFieldRays(const HeightField& field, const std::vector<HeightRay>& rays,
                                           const RayCastOptions& options) {
  const PvsGrid grid = detail::castGrid(options);
  const PvsLayout layout = pvsLayout(field, grid);
  const std::vector<float> heights = detail::rayHeights(field);
  const detail::RayPyramid pyramid = detail::buildRayPyramid(heights, field.width, field.height);
  const int cap = options.view_cells ? layout.view_x + layout.view_y : 0;
  RayCastResult out;
  out.t.resize(rays.size());
  out.cell.resize(rays.size());
  out.first.assign(1, 0);
  std::vector<int> cells(std::max(cap, 1));
  std::vector<float> ts(std::max(cap, 1));
  for (std::size_t r = 0; r < rays.size(); ++r) {
    const HeightRay& q = rays[r];
    int count = 0;
    out.t[r] = detail::hf_ray_cast(
        heights.data(), field.width, field.height, pyramid.values.data(), pyramid.levels.data(), pyramid.top,
        q.ox, q.oy, q.oz, q.dx, q.dy, q.dz, q.t_max, float(options.curvature), float(field.cell_size_x),
        float(field.cell_size_y), grid.view_cell, layout.view_x, float(grid.band_low), float(grid.band_high),
        cap, cells.data(), ts.data(), 1, &count, &out.cell[r]);
    out.view_cell.insert(out.view_cell.end(), cells.begin(), cells.begin() + count);
    out.view_t.insert(out.view_t.end(), ts.begin(), ts.begin() + count);
    out.first.push_back(out.view_cell.size());
  }
  return out;
}

double rayClearance(const HeightField& field, const HeightRay& ray, double t, double curvature) {
  double x = ray.ox + t * double(ray.dx), y = ray.oy + t * double(ray.dy);
  const double gx = ray.dx * field.cell_size_x, gy = ray.dy * field.cell_size_y;
  const double z = ray.oz + t * double(ray.dz) + curvature * (gx * gx + gy * gy) * t * t;
  // Within 1e-4 pixel of the box: on its edge (the caster's float rounding).
  if (!(x >= -1e-4 && y >= -1e-4 && x <= field.width - 1 + 1e-4 && y <= field.height - 1 + 1e-4)) return NAN;
  x = std::clamp(x, 0.0, double(field.width - 1));
  y = std::clamp(y, 0.0, double(field.height - 1));
  // The cell holding the point; within 1e-4 pixel of a grid line (the caster's rounding), any
  // valid cell beside it (the surface is continuous across a line between valid cells).
  const int fx = std::min(int(x), field.width - 2), fy = std::min(int(y), field.height - 2);
  for (int cy = fy - 1; cy <= fy + 1; ++cy)
    for (int cx = fx - 1; cx <= fx + 1; ++cx) {
      if (cx < 0 || cy < 0 || cx > field.width - 2 || cy > field.height - 2) continue;
      if (x < cx - 1e-4 || x > cx + 1 + 1e-4 || y < cy - 1e-4 || y > cy + 1 + 1e-4) continue;
      const double u = std::clamp(x - cx, 0.0, 1.0), v = std::clamp(y - cy, 0.0, 1.0), zs = field.z_scale;
      const double h00 = double(field.at(cx, cy)) * zs, h10 = double(field.at(cx + 1, cy)) * zs,
                   h01 = double(field.at(cx, cy + 1)) * zs, h11 = double(field.at(cx + 1, cy + 1)) * zs;
      const double s = h00 * (1 - u) * (1 - v) + h10 * u * (1 - v) + h01 * (1 - u) * v + h11 * u * v;
      if (std::isfinite(s)) return z - s;
    }
  return NAN;  // over nodata
}

double bruteForceRayHit(const HeightField& field, const HeightRay& ray, double step, double curvature) {
  // Samples midway between the steps: never exactly on the grid point a ray may start from.
  for (double t = 0.5 * step; t <= double(ray.t_max); t += step) {
    const double c = rayClearance(field, ray, t, curvature);
    if (c < 0.0) return t;
    const double x = ray.ox + t * double(ray.dx), y = ray.oy + t * double(ray.dy);
    // Once out of the box moving away, nothing more.
    if ((x < 0 && ray.dx <= 0) || (y < 0 && ray.dy <= 0) || (x > field.width - 1 && ray.dx >= 0) ||
        (y > field.height - 1 && ray.dy >= 0))
      break;
  }
  return INFINITY;
}

std::vector<HeightRay> randomViewRays(const HeightField& f, const PvsGrid& grid, int count,
                                      std::uint32_t seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<HeightRay> rays;
  rays.reserve(count);
  while (static_cast<int>(rays.size()) < count) {
    const double x = u(gen) * (f.width - 1), y = u(gen) * (f.height - 1);
    const int cx = std::min(int(x), f.width - 2), cy = std::min(int(y), f.height - 2);
    const double a = u(gen), b = u(gen);
    const double h00 = f.at(cx, cy), h10 = f.at(cx + 1, cy), h01 = f.at(cx, cy + 1),
                 h11 = f.at(cx + 1, cy + 1);
    const double s = (h00 * (1 - (x - cx)) * (1 - (y - cy)) + h10 * (x - cx) * (1 - (y - cy)) +
                      h01 * (1 - (x - cx)) * (y - cy) + h11 * (x - cx) * (y - cy)) *
                     f.z_scale;
    if (!std::isfinite(s)) continue;
    const double phi = 2.0 * M_PI * a, c = 1.0 - 2.0 * b, r = std::sqrt(std::max(0.0, 1.0 - c * c));
    HeightRay ray;
    ray.ox = float(x), ray.oy = float(y);
    ray.oz = float(s + grid.band_low + (grid.band_high - grid.band_low) * u(gen));
    ray.dx = float(r * std::cos(phi) / f.cell_size_x);
    ray.dy = float(r * std::sin(phi) / f.cell_size_y);
    ray.dz = float(c);
    ray.t_max = INFINITY;
    rays.push_back(ray);
  }
  return rays;
}

double measuredPixelError(const HeightField& f, const PvsResult& pvs, const std::vector<HeightRay>& rays,
                          const RayCastResult& hits, double resolution) {
  std::size_t wrong = 0;
  const PvsLayout& l = pvs.layout;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (hits.cell[i] < 0) continue;
    const int cx = std::min(int(rays[i].ox), f.width - 2), cy = std::min(int(rays[i].oy), f.height - 2);
    const int v = l.viewOfCell(cy * l.cells_x + cx);
    wrong += !pvs.visible(v, l.tileOfCell(hits.cell[i]));
  }
  return resolution * double(wrong) / double(rays.size());
}

}  // namespace hfvis
