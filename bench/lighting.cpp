// bench/lighting.cpp: environment lighting's benchmark (issue 11): time per frame against N and
// K, and the error against a Monte-Carlo ray-traced reference against K and the table's bands.
//
// The reference: per pixel, stratified cosine-weighted directions about the surface normal (the
// library's normal), each marched on the bilinear surface in steps of a twentieth of a pixel until it
// leaves the field (seen: the map's radiance in that direction, nearest pixel) or passes below
// the surface (hidden). The map's brightest pixels (a sun) are left out of the random directions
// and integrated on a 16 x 16 grid of directions each, as they would dominate the variance.
// Two halves of the directions with independent jitter give the reference's own noise.
#include "lighting.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <thread>
#include <vector>

#include "hfvis/environment_light.hpp"
#include "hfvis/horizon.hpp"
#include "core/unit_normals.hpp"
#include "suite_support.hpp"

namespace hfvis::bench {
namespace {

struct Vec {
  double x, y, z;
};

// The map's radiance in direction w (x east = +column, y south = +row, z up), channel c, nearest pixel.
double radiance(const EnvironmentMap& map, int c, const Vec& w) {
  const double zenith = std::acos(std::clamp(w.z, -1.0, 1.0));
  double u = (std::atan2(w.x, -w.y) * 180.0 / M_PI - map.rotation_deg) / 360.0;
  u -= std::floor(u);
  const int col = std::min(map.width - 1, static_cast<int>(u * map.width));
  const int row = std::min(map.height - 1, static_cast<int>(zenith / M_PI * map.height));
  return map.radiance[(static_cast<std::size_t>(c) * map.height + row) * map.width + col];
}

// Whether the ray from pixel (c, r) at its height along w leaves the field above the surface.
bool unoccluded(const HeightField& f, int c, int r, const Vec& w, float top) {
  const double horizontal = std::hypot(w.x, w.y);
  if (horizontal < 1e-9) return true;
  const double gx = w.x / horizontal, gy = w.y / horizontal, slope = w.z / horizontal;
  const double h0 = f.heights[static_cast<std::size_t>(r) * f.width + c];
  const double step = 0.05 * std::min(f.cell_size_x, f.cell_size_y);
  for (double t = step;; t += step) {
    const double px = c + t * gx / f.cell_size_x, py = r + t * gy / f.cell_size_y;
    if (px < 0.0 || py < 0.0 || px > f.width - 1 || py > f.height - 1) return true;
    const double ray = h0 + t * slope;
    if (ray > top) return true;
    const int x0 = std::min(f.width - 2, static_cast<int>(px)), y0 = std::min(f.height - 2, static_cast<int>(py));
    const double fx = px - x0, fy = py - y0;
    auto h = [&](int x, int y) { return double(f.heights[static_cast<std::size_t>(y) * f.width + x]); };
    const double surface = (1 - fx) * (1 - fy) * h(x0, y0) + fx * (1 - fy) * h(x0 + 1, y0) +
                           (1 - fx) * fy * h(x0, y0 + 1) + fx * fy * h(x0 + 1, y0 + 1);
    if (surface > ray + 1e-9) return false;
  }
}

}  // namespace

LightingReference monteCarloIrradiance(const HeightField& field, const EnvironmentMap& map, int samples) {
  const std::size_t pixels = field.pixelCount();
  const std::vector<float> normals = detail::unitNormals(field);
  const float top = *std::max_element(field.heights.begin(), field.heights.end());
  // The brightest pixels of the map: integrated on a grid, not sampled.
  std::vector<float> luminance(static_cast<std::size_t>(map.width) * map.height, 0.0f);
  for (int c = 0; c < map.channels; ++c)
    for (std::size_t i = 0; i < luminance.size(); ++i) luminance[i] += map.radiance[c * luminance.size() + i];
  std::vector<float> sorted = luminance;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const float bright = 50.0f * std::max(sorted[sorted.size() / 2], 1e-6f);
  std::vector<std::size_t> bright_pixels;
  for (std::size_t i = 0; i < luminance.size(); ++i)
    if (luminance[i] > bright) bright_pixels.push_back(i);
  LightingReference out;
  out.channels = map.channels;
  out.bright_pixels = static_cast<int>(bright_pixels.size());
  out.irradiance.assign(pixels * map.channels, 0.0);
  out.noise.assign(pixels * map.channels, 0.0);
  const int side = std::max(1, static_cast<int>(std::sqrt(samples / 2.0)));  // strata per half: side x side
  out.samples = 2 * side * side;
  auto work = [&](std::size_t first, std::size_t step) {
    std::mt19937 rng(static_cast<unsigned>(first) * 7919u + 17u);
    std::uniform_real_distribution<double> jitter(0.0, 1.0);
    std::vector<double> half(2 * map.channels);
    for (std::size_t p = first; p < pixels; p += step) {
      const int c = static_cast<int>(p % field.width), r = static_cast<int>(p / field.width);
      const Vec n{normals[4 * p], normals[4 * p + 1], normals[4 * p + 2]};
      // A frame about n.
      const Vec a = std::fabs(n.z) < 0.9 ? Vec{0, 0, 1} : Vec{1, 0, 0};
      Vec t{a.y * n.z - a.z * n.y, a.z * n.x - a.x * n.z, a.x * n.y - a.y * n.x};
      const double tl = std::sqrt(t.x * t.x + t.y * t.y + t.z * t.z);
      t = {t.x / tl, t.y / tl, t.z / tl};
      const Vec b{n.y * t.z - n.z * t.y, n.z * t.x - n.x * t.z, n.x * t.y - n.y * t.x};
      std::fill(half.begin(), half.end(), 0.0);
      for (int h = 0; h < 2; ++h) {
        for (int i = 0; i < side; ++i) {
          for (int j = 0; j < side; ++j) {
            const double u1 = (i + jitter(rng)) / side, u2 = (j + jitter(rng)) / side;
            const double rad = std::sqrt(u1), phi = 2.0 * M_PI * u2, z = std::sqrt(1.0 - u1);
            const Vec w{rad * std::cos(phi) * t.x + rad * std::sin(phi) * b.x + z * n.x,
                        rad * std::cos(phi) * t.y + rad * std::sin(phi) * b.y + z * n.y,
                        rad * std::cos(phi) * t.z + rad * std::sin(phi) * b.z + z * n.z};
            // The bright pixels come from the grid below.
            const double zenith = std::acos(std::clamp(w.z, -1.0, 1.0));
            double u = (std::atan2(w.x, -w.y) * 180.0 / M_PI - map.rotation_deg) / 360.0;
            u -= std::floor(u);
            const std::size_t at = static_cast<std::size_t>(std::min(map.height - 1, int(zenith / M_PI * map.height))) *
                                       map.width + std::min(map.width - 1, int(u * map.width));
            if (luminance[at] > bright || !unoccluded(field, c, r, w, top)) continue;
            for (int ch = 0; ch < map.channels; ++ch) half[h * map.channels + ch] += radiance(map, ch, w);
          }
        }
      }
      for (int ch = 0; ch < map.channels; ++ch) {
        const double e0 = M_PI * half[ch] / (side * side), e1 = M_PI * half[map.channels + ch] / (side * side);
        out.irradiance[ch * pixels + p] = 0.5 * (e0 + e1);
        out.noise[ch * pixels + p] = 0.5 * std::fabs(e0 - e1);
      }
      // Each bright map pixel on a 16 x 16 grid of directions: L max(0, n . w) dOmega where seen.
      for (std::size_t q : bright_pixels) {
        const int row = static_cast<int>(q / map.width), col = static_cast<int>(q % map.width);
        for (int i = 0; i < 16; ++i) {
          const double zenith = (row + (i + 0.5) / 16.0) * M_PI / map.height;
          for (int j = 0; j < 16; ++j) {
            const double compass = ((col + (j + 0.5) / 16.0) / map.width * 360.0 + map.rotation_deg) * M_PI / 180.0;
            const Vec w{std::sin(zenith) * std::sin(compass), -std::sin(zenith) * std::cos(compass), std::cos(zenith)};
            const double cosine = n.x * w.x + n.y * w.y + n.z * w.z;
            if (cosine <= 0.0 || !unoccluded(field, c, r, w, top)) continue;
            const double solid = std::sin(zenith) * (M_PI / map.height / 16.0) * (2.0 * M_PI / map.width / 16.0);
            for (int ch = 0; ch < map.channels; ++ch)
              out.irradiance[ch * pixels + p] += map.radiance[(static_cast<std::size_t>(ch) * map.height + row) *
                                                                  map.width + col] * cosine * solid;
          }
        }
      }
    }
  };
  std::vector<std::thread> pool;
  const std::size_t n = threads();
  for (std::size_t i = 0; i < n; ++i) pool.emplace_back(work, i, n);
  for (auto& t : pool) t.join();
  return out;
}

double timeEnvironmentLighting(const ComputeContext& context, const HeightField& field, const EnvironmentMap& map,
                               int directions, int reps) {
  HorizonOptions options;
  options.directions = directions;
  HorizonOutputs outputs;
  outputs.environment = &map;
  double best = 1e30;
  for (int i = 0; i < reps; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const HorizonResult r = computeHorizons(context, field, options, outputs);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (r.irradiance.empty()) throw std::runtime_error("no irradiance");
  }
  return best;
}

}  // namespace hfvis::bench
