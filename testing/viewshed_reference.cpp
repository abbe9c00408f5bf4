// viewshed_reference.cpp: see hfvis_testing/viewshed_reference.hpp.
#include "hfvis_testing/viewshed_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hfvis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double heightAt(const HeightField& f, int x, int y) {
  const float v = f.at(x, y);
  return std::isfinite(v) ? v * f.z_scale : kNaN;
}

double eyeHeight(const HeightField& f, const Observer& o, const ViewshedOptions& options) {
  return options.absolute ? o.height : heightAt(f, o.col, o.row) + o.height;
}

bool inRange(const HeightField& f, const Observer& o, const ViewshedOptions& options, int col, int row,
             double angle) {
  const double gx = (col - o.col) * f.cell_size_x, gy = (row - o.row) * f.cell_size_y;
  const double dist = std::hypot(gx, gy);
  if (options.max_distance > 0.0 && dist > options.max_distance) return false;
  if (angle < options.elevation_min_deg * M_PI / 180.0 || angle > options.elevation_max_deg * M_PI / 180.0)
    return false;
  double span = std::fmod(options.azimuth_to_deg - options.azimuth_from_deg, 360.0);
  if (span < 0.0) span += 360.0;
  if (span > 0.0 && dist > 0.0) {  // 0: the whole circle
    double from_start = std::fmod(std::atan2(gx, -gy) * 180.0 / M_PI - options.azimuth_from_deg, 360.0);
    if (from_start < 0.0) from_start += 360.0;
    if (from_start > span) return false;
  }
  return true;
}

}  // namespace

SightLine referenceSightLine(const HeightField& f, const Observer& o, const ViewshedOptions& options, int col,
                             int row) {
  const double ze = eyeHeight(f, o, options);
  const double dx = col - o.col, dy = row - o.row;
  const double d2 = std::pow(dx * f.cell_size_x, 2) + std::pow(dy * f.cell_size_y, 2);
  const double drop = options.curvature * d2;
  const double zt = heightAt(f, col, row) + options.target_height - drop;
  // The heights' rounding, which the sight line forgives (forgiven_rise in kernels/viewshed.cl).
  const double forgiven = std::ldexp(std::fabs(ze) + std::fabs(zt + drop) + std::fabs(drop), -21);
  // Where the line crosses grid lines, in order: (t, column line i or -1, row line j or -1);
  // both at a grid point.
  struct Crossing {
    double t;
    int i, j;
  };
  std::vector<Crossing> cs = {{0.0, o.col, o.row}, {1.0, col, row}};
  for (int i = std::min(o.col, col) + 1; i < std::max(o.col, col); ++i) cs.push_back({(i - o.col) / dx, i, -1});
  for (int j = std::min(o.row, row) + 1; j < std::max(o.row, row); ++j) cs.push_back({(j - o.row) / dy, -1, j});
  std::sort(cs.begin(), cs.end(), [](const Crossing& a, const Crossing& b) { return a.t < b.t; });
  std::vector<Crossing> merged;
  for (const Crossing& c : cs) {
    if (!merged.empty() && c.t - merged.back().t < 1e-12) {
      if (c.i >= 0) merged.back().i = c.i;
      if (c.j >= 0) merged.back().j = c.j;
      continue;
    }
    merged.push_back(c);
  }
  auto line = [&](double t) { return ze + t * (zt - ze) + drop * t * t; };  // the sight line, curvature added back
  // f at a crossing: the surface on the grid line there (the linear interpolation between the
  // grid line's two heights around it, valid where both are), less the sight line.
  auto atCrossing = [&](const Crossing& c) {
    if (c.t == 0.0) return heightAt(f, o.col, o.row) - ze;
    if (c.t == 1.0) return std::isnan(heightAt(f, col, row)) ? kNaN : -options.target_height;
    double h;
    if (c.i >= 0 && c.j >= 0) {
      h = heightAt(f, c.i, c.j);
    } else if (c.i >= 0) {
      const double y = o.row + c.t * dy;
      const int j = std::clamp(static_cast<int>(std::floor(y)), 0, f.height - 1), j1 = std::min(j + 1, f.height - 1);
      h = y == j ? heightAt(f, c.i, j) : heightAt(f, c.i, j) + (heightAt(f, c.i, j1) - heightAt(f, c.i, j)) * (y - j);
    } else {
      const double x = o.col + c.t * dx;
      const int i = std::clamp(static_cast<int>(std::floor(x)), 0, f.width - 1), i1 = std::min(i + 1, f.width - 1);
      h = x == i ? heightAt(f, i, c.j) : heightAt(f, i, c.j) + (heightAt(f, i1, c.j) - heightAt(f, i, c.j)) * (x - i);
    }
    return h - line(c.t);
  };
  // f inside cell (cx, cy): the bilinear surface less the sight line.
  auto inCell = [&](int cx, int cy, double t) {
    const double x = o.col + t * dx, y = o.row + t * dy;
    const int x1 = std::min(cx + 1, f.width - 1), y1 = std::min(cy + 1, f.height - 1);
    const double u = x - cx, v = y - cy;
    const double top = heightAt(f, cx, cy) + (heightAt(f, x1, cy) - heightAt(f, cx, cy)) * u;
    const double bottom = heightAt(f, cx, y1) + (heightAt(f, x1, y1) - heightAt(f, cx, y1)) * u;
    return top + (bottom - top) * v - line(t);
  };
  // What the line forgives over cell (cx, cy): `forgiven`, or where more 2^-21 of the cell's largest
  // |corner| (cell_forgiven in kernels/viewshed.cl: the surface there rounds by units in the last
  // place of its corners).
  auto cellForgiven = [&](int cx, int cy) {
    const int x1 = std::min(cx + 1, f.width - 1), y1 = std::min(cy + 1, f.height - 1);
    double corners = 0.0;
    for (const double v :
         {heightAt(f, cx, cy), heightAt(f, x1, cy), heightAt(f, cx, y1), heightAt(f, x1, y1)})
      if (!std::isnan(v)) corners = std::max(corners, std::fabs(v));
    return std::max(forgiven, std::ldexp(corners, -21));
  };
  bool hidden = false;
  double rise = -std::numeric_limits<double>::infinity(), interior = rise, excess = rise;
  std::vector<double> fs(merged.size());
  for (std::size_t s = 0; s < merged.size(); ++s) {
    fs[s] = atCrossing(merged[s]);
    if (std::isnan(fs[s])) continue;
    rise = std::max(rise, fs[s]);
    if (s > 0 && s + 1 < merged.size()) interior = std::max(interior, fs[s]);
    if (s > 0) excess = std::max(excess, fs[s] / merged[s].t);
  }
  for (std::size_t s = 0; s + 1 < merged.size(); ++s) {
    const double t0 = merged[s].t, t1 = merged[s + 1].t, tm = 0.5 * (t0 + t1);
    const int cx = std::clamp(static_cast<int>(std::floor(o.col + tm * dx)), 0, std::max(f.width - 2, 0));
    const int cy = std::clamp(static_cast<int>(std::floor(o.row + tm * dy)), 0, std::max(f.height - 2, 0));
    const int x1 = std::min(cx + 1, f.width - 1), y1 = std::min(cy + 1, f.height - 1);
    const double tolerance = cellForgiven(cx, cy);
    hidden = hidden || fs[s] > tolerance || fs[s + 1] > tolerance;
    // Along a grid line (dx dy = 0) the surface is the edge's straight line, beside nodata too.
    const double twist =
        dx * dy != 0.0 ? heightAt(f, cx, cy) - heightAt(f, x1, cy) - heightAt(f, cx, y1) + heightAt(f, x1, y1) : 0.0;
    if (std::isnan(twist) || std::isnan(fs[s]) || std::isnan(fs[s + 1]))
      continue;  // a cell with a nodata corner has no surface inside
    const double a = twist * dx * dy - drop;  // t^2 coefficient of f
    if (s == 0) {                             // f / t next to the eye
      if (fs[0] > 0.0) excess = std::numeric_limits<double>::infinity();
      if (fs[0] == 0.0) excess = std::max(excess, (fs[1] - fs[0]) / t1 - a * t1);
    }
    if (a < 0.0) {  // where (f / t)' = 0: t^2 = t0 t1 + f_lin(0) / a
      const double tt = t0 * t1 + (fs[s] * t1 - fs[s + 1] * t0) / (t1 - t0) / a;
      const double tv = tt > 0.0 ? std::sqrt(tt) : 0.0;
      if (tv > t0 && tv < t1) excess = std::max(excess, inCell(cx, cy, tv) / tv);
    }
    if (a < 0.0) {
      const double tv = -(((fs[s + 1] - fs[s]) / (t1 - t0)) - a * (t0 + t1)) / (2.0 * a);  // vertex of f
      if (tv > t0 && tv < t1) {
        rise = std::max(rise, inCell(cx, cy, tv));
        interior = std::max(interior, inCell(cx, cy, tv));
        hidden = hidden || inCell(cx, cy, tv) > tolerance;
      }
    }
  }
  return {!hidden, rise, interior, excess};
}

ViewshedResult referenceViewshed(const HeightField& f, const Observer& o, const ViewshedOptions& options,
                                 std::vector<double>* rises) {
  ViewshedResult r;
  r.width = f.width;
  r.height = f.height;
  r.visible.assign(f.pixelCount(), 0.0f);
  r.angle.assign(f.pixelCount(), 0.0f);
  r.needed_height.assign(f.pixelCount(), std::numeric_limits<float>::quiet_NaN());
  if (rises) rises->assign(f.pixelCount(), kNaN);
  const double ze = eyeHeight(f, o, options);
  for (int row = 0; row < f.height; ++row)
    for (int col = 0; col < f.width; ++col) {
      const std::size_t p = static_cast<std::size_t>(row) * f.width + col;
      const double h = heightAt(f, col, row);
      if (std::isnan(h)) {
        r.visible[p] = r.angle[p] = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      const double gx = (col - o.col) * f.cell_size_x, gy = (row - o.row) * f.cell_size_y;
      const double d2 = gx * gx + gy * gy, dist = std::sqrt(d2);
      const double rise = h + options.target_height - options.curvature * d2 - ze;
      const double angle = dist > 0.0 ? std::atan2(rise, dist) : (rise >= 0.0 ? M_PI / 2 : -M_PI / 2);
      r.angle[p] = static_cast<float>(angle);
      if (!inRange(f, o, options, col, row, angle)) continue;
      if (dist == 0.0) {
        r.visible[p] = 1.0f;
        r.needed_height[p] = 0.0f;
        continue;
      }
      const SightLine s = referenceSightLine(f, o, options, col, row);
      r.visible[p] = s.visible ? 1.0f : 0.0f;
      r.needed_height[p] = static_cast<float>(std::max(0.0, options.target_height + s.excess));
      // 0 where a target on the surface is seen (its line grazing within the rounding forgiven).
      if (r.needed_height[p] > 0.0f) {
        ViewshedOptions on_surface = options;
        on_surface.target_height = 0.0;
        if (referenceSightLine(f, o, on_surface, col, row).visible) r.needed_height[p] = 0.0f;
      }
      if (rises) (*rises)[p] = s.rise;
    }
  return r;
}

std::vector<float> referenceCulledMask(const HeightField& f, const ViewshedPyramid& pyramid, const Observer& o,
                                       const ViewshedOptions& options) {
  const double ze = eyeHeight(f, o, options), c = pyramid.curvature;
  constexpr int kFloats = ViewshedPyramid::kRegionFloats;
  // The bound of a region at distance r: linear between the breakpoints; NaN past the reach.
  auto bound = [&](const float* region, double r) {
    for (int i = 0; i + 1 < ViewshedPyramid::kBreakpoints; ++i) {
      const double b0 = pyramid.reach * ViewshedPyramid::breakFraction(i);
      const double b1 = pyramid.reach * ViewshedPyramid::breakFraction(i + 1);
      if (r <= b1) {
        const double a = region[1 + i], b = region[2 + i];
        return a == b ? a : a + (b - a) * (r - b0) / (b1 - b0);
      }
    }
    return std::numeric_limits<double>::quiet_NaN();
  };
  auto culls = [&](const ViewshedPyramid::Level& level, int nx, int ny) {
    const int side = 1 << level.k;
    const int x0 = nx * side, y0 = ny * side;
    const int x1 = std::min(x0 + side, f.width) - 1, y1 = std::min(y0 + side, f.height) - 1;
    const double hx = 0.5 * (x1 - x0) * f.cell_size_x, hy = 0.5 * (y1 - y0) * f.cell_size_y;
    const double gx = (o.col - 0.5 * (x0 + x1)) * f.cell_size_x, gy = (o.row - 0.5 * (y0 + y1)) * f.cell_size_y;
    const double rc = std::hypot(gx, gy), rho = std::hypot(hx, hy);
    const double r_lo = rc - rho, r_hi = rc + rho;
    if (!(r_lo > 0.0)) return false;
    const double alpha = std::asin(std::min(1.0, rho / rc)), phi = std::atan2(gy, gx);
    const double lhs = ze - c * (c >= 0.0 ? r_lo * r_lo : r_hi * r_hi);
    for (int s = 0; s < pyramid.sectors; ++s) {
      // Does [phi - alpha, phi + alpha] meet [start, start + width] (modulo 2 pi)?
      const double start = pyramid.sector_start[s], width = pyramid.sector_width[s];
      double rel = std::fmod(phi - alpha - start, 2.0 * M_PI);
      if (rel < 0.0) rel += 2.0 * M_PI;
      if (!(rel <= width || rel + 2.0 * alpha >= 2.0 * M_PI)) continue;
      const float* region = &level.regions[((std::size_t(ny) * level.nodes_x + nx) * pyramid.sectors + s) * kFloats];
      const double b_lo = bound(region, r_lo), b_hi = bound(region, r_hi);
      if (std::isnan(b_lo) || std::isnan(b_hi) || !(r_lo > region[0] && lhs < std::min(b_lo, b_hi))) return false;
    }
    return true;
  };
  // From the coarsest level down: a node is culled when its parent is or when it passes.
  std::vector<unsigned char> parent;
  int parent_nx = 0;
  for (auto level = pyramid.levels.rbegin(); level != pyramid.levels.rend(); ++level) {
    std::vector<unsigned char> flags(std::size_t(level->nodes_x) * level->nodes_y);
    for (int ny = 0; ny < level->nodes_y; ++ny)
      for (int nx = 0; nx < level->nodes_x; ++nx)
        flags[std::size_t(ny) * level->nodes_x + nx] =
            (!parent.empty() && parent[std::size_t(ny >> 1) * parent_nx + (nx >> 1)]) || culls(*level, nx, ny);
    parent = std::move(flags);
    parent_nx = level->nodes_x;
  }
  const int k = pyramid.levels.front().k;
  std::vector<float> mask(f.pixelCount());
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const std::size_t p = std::size_t(y) * f.width + x;
      mask[p] = !std::isfinite(f.heights[p]) ? std::numeric_limits<float>::quiet_NaN()
                                              : parent[std::size_t(y >> k) * parent_nx + (x >> k)] ? 1.0f : 0.0f;
    }
  return mask;
}

}  // namespace hfvis
