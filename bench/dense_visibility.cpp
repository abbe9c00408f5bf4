// bench/dense_visibility.cpp: see dense_visibility.hpp.
#include "dense_visibility.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

namespace hfvis::bench {

namespace {

// Components this small are rounding noise of an axis direction (cos(pi / 2)): 0, as the
// library snaps them, so that such rays run along the pixel rows or columns.
double snap(double v) { return std::abs(v) < 1e-12 ? 0.0 : v; }

struct Ray {
  double dx, dy;  // one pixel length along the ray, in pixel axes
};

}  // namespace

std::vector<double> denseVisibleCounts(const HeightField& field, const SweepOptions& options, int per_unit) {
  std::vector<DenseRay> rays;
  for (int k = 0; k < options.directions; ++k) rays.push_back({directionAzimuth(k, options), 1.0});
  return denseVisibleCounts(field, rays, per_unit);
}

std::vector<DenseRay> azimuthDenseRays(int n) {
  std::vector<DenseRay> rays;
  for (int k = 0; k < n; ++k) rays.push_back({2.0 * M_PI * k / n, 1.0 / n});
  return rays;
}

std::vector<double> denseVisibleCounts(const HeightField& field, const std::vector<DenseRay>& rays,
                                       int per_unit) {
  const auto lengths = denseVisibleLengths(field, rays, per_unit);
  std::vector<double> counts(field.pixelCount(), 0.0);
  for (std::size_t j = 0; j < rays.size(); ++j)
    for (std::size_t i = 0; i < counts.size(); ++i) counts[i] += rays[j].weight * lengths[j][i];
  return counts;
}

std::vector<std::vector<double>> denseVisibleLengths(const HeightField& field,
                                                     const std::vector<DenseRay>& directions, int per_unit) {
  const int w = field.width, h = field.height;
  double lowest = std::numeric_limits<double>::max(), highest = std::numeric_limits<double>::lowest();
  for (float v : field.heights) lowest = std::min(lowest, double(v)), highest = std::max(highest, double(v));
  std::vector<double> z(field.heights.size());
  for (std::size_t i = 0; i < z.size(); ++i) z[i] = (double(field.heights[i]) - lowest) * field.z_scale;
  // Height tolerance of a tie (see the header): a sample is visible when
  // h(t) - h0 >= best_slope * t - tolerance.
  const double tolerance = kDenseTieTolerance * (highest - lowest) * field.z_scale;

  std::vector<Ray> rays;
  for (const DenseRay& d : directions) {
    double px = snap(std::cos(d.azimuth)) / field.cell_size_x,
           py = snap(std::sin(d.azimuth)) / field.cell_size_y;
    const double norm = std::hypot(px, py);
    rays.push_back({px / norm, py / norm});
  }
  const double step = 1.0 / per_unit;
  // Bilinear height at (x, y) inside the domain, as a + (b - a) f (exact where the corners
  // are equal).
  auto at = [&](double x, double y) {
    x = std::min(std::max(x, 0.0), double(w - 1));
    y = std::min(std::max(y, 0.0), double(h - 1));
    const int x0 = std::min(static_cast<int>(x), std::max(w - 2, 0));
    const int y0 = std::min(static_cast<int>(y), std::max(h - 2, 0));
    const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
    const double fx = x - x0, fy = y - y0;
    const double* row0 = &z[static_cast<std::size_t>(y0) * w];
    const double* row1 = &z[static_cast<std::size_t>(y1) * w];
    const double top = row0[x0] + (row0[x1] - row0[x0]) * fx;
    const double bottom = row1[x0] + (row1[x1] - row1[x0]) * fx;
    return top + (bottom - top) * fy;
  };

  std::vector<std::vector<double>> lengths(rays.size(), std::vector<double>(field.pixelCount(), 0.0));
  std::atomic<int> next_row{0};
  auto worker = [&] {
    for (int r = next_row++; r < h; r = next_row++) {
      for (int c = 0; c < w; ++c) {
        const double h0 = z[static_cast<std::size_t>(r) * w + c];
        for (std::size_t k = 0; k < rays.size(); ++k) {
          const Ray& ray = rays[k];
          long visible = 0;
          // The ray leaves [0, W-1] x [0, H-1] at t_max; samples at j / D <= t_max (within
          // 1e-9 pixel) are inside.
          const double inf = std::numeric_limits<double>::infinity();
          const double tx = ray.dx > 0 ? (w - 1 - c) / ray.dx : ray.dx < 0 ? c / -ray.dx : inf;
          const double ty = ray.dy > 0 ? (h - 1 - r) / ray.dy : ray.dy < 0 ? r / -ray.dy : inf;
          const long n = static_cast<long>(std::floor((std::min(tx, ty) + 1e-9) * per_unit));
          double best = -inf;  // the largest slope so far
          for (long j = 1; j <= n; ++j) {
            const double t = j * step;
            const double rise = at(c + t * ray.dx, r + t * ray.dy) - h0;
            if (rise >= best * t - tolerance) ++visible;
            best = std::max(best, rise / t);
          }
          lengths[k][static_cast<std::size_t>(r) * w + c] = double(visible) / per_unit;
        }
      }
    }
  };
  const int n_threads = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (int i = 0; i < n_threads; ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  return lengths;
}

namespace {

// splitmix64: a small deterministic generator whose sequence does not depend on the
// standard library (std::uniform_int_distribution's does).
struct Generator {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t x = (state += 0x9E3779B97F4A7C15ull);
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  }
  int between(int lo, int hi) {
    return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
  }
};

// [start, end) spans of city blocks along one axis of length n: streets of 4-6 pixels
// between blocks of 30-60 (a street first, so the field's edge is a street).
std::vector<std::pair<int, int>> cityBlocks(int n, Generator& g) {
  std::vector<std::pair<int, int>> blocks;
  for (int x = g.between(0, 6); x < n;) {
    const int street = g.between(4, 6), block = g.between(30, 60);
    const int start = x + street, end = std::min(n, start + block);
    if (end - start >= 4) blocks.emplace_back(start, end);
    x = start + block;
  }
  return blocks;
}

}  // namespace

HeightField makeCityField(int width, int height, std::uint32_t seed) {
  HeightField f;
  f.width = width;
  f.height = height;
  f.heights.resize(f.pixelCount());
  // Slopes 1/32 and 1/64: every ground height is exact in float, so the ground is a true
  // plane (its exact ties stay ties in the reference).
  auto ground = [](int c, int r) { return c / 32.0 + r / 64.0; };
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) f.heights[static_cast<std::size_t>(r) * width + c] = float(ground(c, r));
  Generator g{seed * 0x2545F4914F6CDD1Dull + 1};
  std::vector<char> built(f.pixelCount(), 0);
  const auto columns = cityBlocks(width, g), rows = cityBlocks(height, g);
  for (const auto& [r0, r1] : rows) {
    for (const auto& [c0, c1] : columns) {
      // Greedy placement: random footprints, kept where they and an alley around them are
      // free, until the block is full (many more attempts than buildings fit).
      const int attempts = 4 * (r1 - r0) * (c1 - c0) / 16 + 20;
      for (int a = 0; a < attempts; ++a) {
        const int bw = g.between(4, 20), bh = g.between(4, 20), alley = g.between(1, 3);
        if (bw > c1 - c0 || bh > r1 - r0) continue;
        const int x = g.between(c0, c1 - bw), y = g.between(r0, r1 - bh);
        bool free = true;
        for (int r = std::max(r0, y - alley); free && r < std::min(r1, y + bh + alley); ++r)
          for (int c = std::max(c0, x - alley); free && c < std::min(c1, x + bw + alley); ++c)
            free = !built[static_cast<std::size_t>(r) * width + c];
        if (!free) continue;
        double base = 0.0;
        for (int r = y; r < y + bh; ++r)
          for (int c = x; c < x + bw; ++c) base = std::max(base, ground(c, r));
        const float roof = float(base + 0.25 * g.between(20, 160));  // 5 .. 40, exact in float
        for (int r = y; r < y + bh; ++r)
          for (int c = x; c < x + bw; ++c) {
            built[static_cast<std::size_t>(r) * width + c] = 1;
            f.heights[static_cast<std::size_t>(r) * width + c] = roof;
          }
      }
    }
  }
  return f;
}

}  // namespace hfvis::bench
