// bench/ground_truth.cpp: exact horizons of the bilinear surface (the benchmark's oracle),
// their disk cache and their self-checks.
#include "ground_truth.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <thread>

#include "hfvis/errors.hpp"

namespace hfvis::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Bump when the oracle's definition changes, so stale cache files are not read.
constexpr const char* kTruthVersion = "hfvis-ground-truth-v1";

// The height at a grid point times z_scale; NaN where it is nodata (any non-finite height).
double heightAt(const HeightField& f, int col, int row) {
  const float v = f.heights[static_cast<std::size_t>(row) * f.width + col];
  return std::isfinite(v) ? static_cast<double>(v) * f.z_scale : std::numeric_limits<double>::quiet_NaN();
}

// Largest t at which the ray is still inside [0, W-1] x [0, H-1].
double exitDistance(const HeightField& f, int c, int r, const Ray& ray) {
  const double tx = ray.dx > 0 ? (f.width - 1 - c) / ray.dx : ray.dx < 0 ? c / -ray.dx : kInf;
  const double ty = ray.dy > 0 ? (f.height - 1 - r) / ray.dy : ray.dy < 0 ? r / -ray.dy : kInf;
  return std::min(tx, ty);
}

double bilinear(const HeightField& f, double x, double y) {
  x = std::clamp(x, 0.0, f.width - 1.0);
  y = std::clamp(y, 0.0, f.height - 1.0);
  const int i = std::min(static_cast<int>(x), f.width - 2), j = std::min(static_cast<int>(y), f.height - 2);
  const double u = x - i, v = y - j;
  const double top = heightAt(f, i, j) + u * (heightAt(f, i + 1, j) - heightAt(f, i, j));
  const double bottom = heightAt(f, i, j + 1) + u * (heightAt(f, i + 1, j + 1) - heightAt(f, i, j + 1));
  return top + v * (bottom - top);
}

std::uint64_t fnv1a(std::uint64_t hash, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * 1099511628211ull;
  return hash;
}

std::uint64_t fieldHash(const HeightField& f) {
  std::uint64_t h = 1469598103934665603ull;
  h = fnv1a(h, kTruthVersion, std::char_traits<char>::length(kTruthVersion));
  h = fnv1a(h, &f.width, sizeof f.width);
  h = fnv1a(h, &f.height, sizeof f.height);
  h = fnv1a(h, f.heights.data(), f.heights.size() * sizeof(float));
  h = fnv1a(h, &f.cell_size_x, sizeof(double));
  h = fnv1a(h, &f.cell_size_y, sizeof(double));
  return fnv1a(h, &f.z_scale, sizeof(double));
}

// `count` receivers drawn without replacement (all when there are fewer) among the pixels with a
// height: a nodata pixel receives nothing (a method's NaN at a receiver is counted apart, err_nan).
std::vector<std::int32_t> chooseReceivers(const HeightField& f, int count) {
  std::vector<std::int32_t> valid;
  for (std::size_t p = 0; p < f.pixelCount(); ++p)
    if (std::isfinite(f.heights[p])) valid.push_back(static_cast<std::int32_t>(p));
  if (count <= 0 || static_cast<std::size_t>(count) >= valid.size()) return valid;
  std::mt19937_64 rng(20240003);
  std::uniform_int_distribution<std::size_t> pick(0, valid.size() - 1);
  std::vector<bool> taken(valid.size(), false);
  std::vector<std::int32_t> chosen;
  while (chosen.size() < static_cast<std::size_t>(count)) {
    const std::size_t n = pick(rng);
    if (!taken[n]) taken[n] = true, chosen.push_back(valid[n]);
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

bool readCache(const std::string& path, GroundTruth& truth) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  char magic[8];
  std::int32_t header[4];
  in.read(magic, 8);
  in.read(reinterpret_cast<char*>(header), sizeof header);
  if (!in || std::string(magic, 8) != "HFVISGT1") return false;
  truth.width = header[0], truth.height = header[1], truth.directions = header[2];
  truth.receivers.resize(header[3]);
  truth.angles.resize(static_cast<std::size_t>(header[3]) * header[2]);
  in.read(reinterpret_cast<char*>(truth.receivers.data()), truth.receivers.size() * sizeof(std::int32_t));
  in.read(reinterpret_cast<char*>(truth.angles.data()), truth.angles.size() * sizeof(double));
  return static_cast<bool>(in);
}

void writeCache(const std::string& path, const GroundTruth& truth) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary);
    const std::int32_t header[4] = {truth.width, truth.height, truth.directions,
                                    static_cast<std::int32_t>(truth.receivers.size())};
    out.write("HFVISGT1", 8);
    out.write(reinterpret_cast<const char*>(header), sizeof header);
    out.write(reinterpret_cast<const char*>(truth.receivers.data()),
              truth.receivers.size() * sizeof(std::int32_t));
    out.write(reinterpret_cast<const char*>(truth.angles.data()), truth.angles.size() * sizeof(double));
    if (!out) throw IoError(temporary, "cannot write the ground-truth cache");
  }
  std::filesystem::rename(temporary, path);
}

}  // namespace

Ray rayForAzimuth(const HeightField& field, double azimuth) {
  // Components this small are rounding noise of an axis-aligned azimuth (as in the library).
  auto snap = [](double v) { return std::abs(v) < 1e-12 ? 0.0 : v; };
  double px = snap(std::cos(azimuth)) / field.cell_size_x, py = snap(std::sin(azimuth)) / field.cell_size_y;
  const double norm = std::hypot(px, py);
  px /= norm, py /= norm;
  return {px, py, std::hypot(px * field.cell_size_x, py * field.cell_size_y)};
}

double exactHorizon(const HeightField& f, int c, int r, const Ray& ray) {
  const double h0 = heightAt(f, c, r);
  if (!std::isfinite(h0)) return std::numeric_limits<double>::quiet_NaN();  // a nodata receiver
  const double t_end = exitDistance(f, c, r, ray);
  if (!(t_end > 0.0)) return -0.5 * kPi;
  const double ax = std::abs(ray.dx), ay = std::abs(ray.dy);
  const int sx = ray.dx > 0 ? 1 : -1, sy = ray.dy > 0 ? 1 : -1;
  double best = -kInf;  // steepest rise per unit t so far
  // The surface at the piece end t on the grid lines the march knows it lies on (`column`,
  // `row`: their indices, -1 when not on one; a ray along an axis stays on its receiver's line):
  // a grid point's own height, an edge's interpolation between its two ends; NaN where one is
  // nodata (the nodata rule: an edge with a nodata end has no surface along it).
  auto on_lines = [&](double t, long column, long row) {
    if (ray.dx == 0.0) column = c;
    if (ray.dy == 0.0) row = r;
    const double x = column >= 0 ? double(column) : std::clamp(c + t * ray.dx, 0.0, f.width - 1.0);
    const double y = row >= 0 ? double(row) : std::clamp(r + t * ray.dy, 0.0, f.height - 1.0);
    const int i = static_cast<int>(x), j = static_cast<int>(y);
    if (x == i && y == j) return heightAt(f, i, j);
    if (x == i) return heightAt(f, i, j) + (y - j) * (heightAt(f, i, j + 1) - heightAt(f, i, j));
    if (y == j) return heightAt(f, i, j) + (x - i) * (heightAt(f, i + 1, j) - heightAt(f, i, j));
    return std::numeric_limits<double>::quiet_NaN();  // (not on a grid line: not reached)
  };
  double t0 = 0.0;
  long column0 = c, row0 = r;  // the lines the piece's start lies on (the receiver: both)
  // The receiver is a grid point, so the ray crosses column lines at t = k / |dx| and row
  // lines at t = m / |dy|; between consecutive crossings it stays in one cell.
  long kx = 1, ky = 1;
  while (t0 < t_end) {
    const double nx = ax > 0.0 ? kx / ax : kInf, ny = ay > 0.0 ? ky / ay : kInf;
    const double t1 = std::min({nx, ny, t_end});
    // Crossings within rounding of each other are one, at a grid point: along a diagonal
    // cos(phi) and sin(phi) differ in their last bits, and the two lines' crossings by a
    // rounding, which would put the point on an edge beside it (one with a nodata end, so
    // losing a valid grid point) instead of on it.
    const double together = t1 * (1.0 + 1e-12);
    const bool on_column = nx <= together, on_row = ny <= together;
    const long column1 = on_column ? c + sx * kx : -1, row1 = on_row ? r + sy * ky : -1;
    if (on_column) ++kx;
    if (on_row) ++ky;
    const double tm = 0.5 * (t0 + t1);
    const int i = std::clamp(static_cast<int>(std::floor(c + tm * ray.dx)), 0, f.width - 2);
    const int j = std::clamp(static_cast<int>(std::floor(r + tm * ray.dy)), 0, f.height - 2);
    const double h00 = heightAt(f, i, j), h10 = heightAt(f, i + 1, j);
    const double h01 = heightAt(f, i, j + 1), h11 = heightAt(f, i + 1, j + 1);
    if (!std::isfinite(h00 + h10 + h01 + h11)) {
      // A cell with a nodata corner has no surface inside: only the piece's ends, on the grid
      // lines, can be surface (along an axis the piece runs on an edge, a straight line whose
      // rise per unit t is steepest at an end).
      if (t0 > 0.0) best = std::max(best, (on_lines(t0, column0, row0) - h0) / t0);
      best = std::max(best, (on_lines(t1, column1, row1) - h0) / t1);
    } else {
      const double e = h10 - h00, g = h01 - h00, q = h00 - h10 - h01 + h11;
      const double u0 = c - i, v0 = r - j;  // cell coordinates of the receiver (t = 0)
      // h(t) - h0 = A t^2 + B t + C on this piece; rise per unit t is A t + B + C / t.
      const double a = q * ray.dx * ray.dy;
      const double b = e * ray.dx + g * ray.dy + q * (u0 * ray.dy + v0 * ray.dx);
      const double cc = h00 + e * u0 + g * v0 + q * u0 * v0 - h0;
      best = std::max(best, a * t1 + b + cc / t1);
      if (t0 == 0.0) best = std::max(best, b);  // the limit t -> 0: the surface's own slope
      if (a != 0.0 && cc / a > 0.0) {           // stationary point A t^2 = C inside the piece
        const double ts = std::sqrt(cc / a);
        if (ts > t0 && ts < t1) best = std::max(best, 2.0 * a * ts + b);
      }
    }
    t0 = t1, column0 = column1, row0 = row1;
  }
  return std::atan2(best, ray.ground_per_unit);
}

double denseHorizon(const HeightField& f, int c, int r, const Ray& ray, double step) {
  const double t_end = exitDistance(f, c, r, ray);
  if (!(t_end > 0.0)) return -0.5 * kPi;
  const double h0 = heightAt(f, c, r);
  double best = -kInf;
  for (long i = 1;; ++i) {
    const double t = std::min(i * step, t_end);
    best = std::max(best, (bilinear(f, c + t * ray.dx, r + t * ray.dy) - h0) / t);
    if (t >= t_end) break;
  }
  return std::atan2(best, ray.ground_per_unit);
}

GroundTruth computeGroundTruth(const HeightField& field, int directions, int receiver_count, int threads) {
  if (field.width < 2 || field.height < 2)
    throw InvalidArgument("ground truth needs a field of at least 2 x 2");
  const auto start = std::chrono::steady_clock::now();
  GroundTruth truth;
  truth.width = field.width;
  truth.height = field.height;
  truth.directions = directions;
  truth.receivers = chooseReceivers(field, receiver_count);
  truth.angles.assign(truth.receivers.size() * directions, 0.0);
  std::vector<Ray> rays;
  for (int k = 0; k < directions; ++k) rays.push_back(rayForAzimuth(field, 2.0 * kPi * k / directions));
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    constexpr std::size_t kChunk = 8;
    for (std::size_t first; (first = next.fetch_add(kChunk)) < truth.receivers.size();) {
      for (std::size_t n = first; n < std::min(first + kChunk, truth.receivers.size()); ++n) {
        const int c = truth.receivers[n] % field.width, r = truth.receivers[n] / field.width;
        for (int k = 0; k < directions; ++k)
          truth.angles[n * directions + k] = exactHorizon(field, c, r, rays[k]);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::max(threads, 1); ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  truth.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return truth;
}

GroundTruth cachedGroundTruth(const HeightField& field, const std::string& label, int directions,
                              int receiver_count, int threads, const std::string& cache_dir) {
  char name[160];
  std::snprintf(name, sizeof name, "%s_%016llx_k%d_r%d.gt", label.c_str(),
                static_cast<unsigned long long>(fieldHash(field)), directions, receiver_count);
  const std::string path = (std::filesystem::path(cache_dir) / name).string();
  GroundTruth truth;
  if (readCache(path, truth) && truth.width == field.width && truth.height == field.height &&
      truth.directions == directions) {
    truth.from_cache = true;
    return truth;
  }
  truth = computeGroundTruth(field, directions, receiver_count, threads);
  std::filesystem::create_directories(cache_dir);
  writeCache(path, truth);
  return truth;
}

std::vector<std::string> checkGroundTruth(std::string* summary) {
  std::vector<std::string> failures;
  auto expect = [&](const std::string& what, double got, double want, double tolerance) {
    if (!(std::abs(got - want) <= tolerance)) {
      std::ostringstream s;
      s.precision(12);
      s << what << ": got " << got << ", expected " << want << " (tolerance " << tolerance << ")";
      failures.push_back(s.str());
    }
  };
  auto field = [](int w, int h, double cx, double cy, auto height_of) {
    HeightField f;
    f.width = w, f.height = h, f.cell_size_x = cx, f.cell_size_y = cy;
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) f.heights.push_back(static_cast<float>(height_of(c, r)));
    return f;
  };

  // A tilted plane is its own bilinear interpolant: every direction sees its own gradient,
  // also with non-square cells. Border pixels looking out of the field see -pi/2.
  const HeightField plane =
      field(9, 7, 2.0, 3.0, [](int c, int r) { return 0.25 * c * 2.0 - 0.5 * r * 3.0; });
  for (int k = 0; k < 16; ++k) {
    const Ray ray = rayForAzimuth(plane, 2.0 * kPi * k / 16);
    const double slope = 0.25 * std::cos(2.0 * kPi * k / 16) - 0.5 * std::sin(2.0 * kPi * k / 16);
    expect("tilted plane, direction " + std::to_string(k), exactHorizon(plane, 4, 3, ray), std::atan(slope),
           1e-12);
  }
  expect("border pixel looking out", exactHorizon(plane, 8, 3, rayForAzimuth(plane, 0.0)), -0.5 * kPi, 0.0);

  // A wall of height 7 from column 12 on: the bilinear ramp 11..12 peaks at its top.
  const HeightField wall = field(20, 5, 1.0, 1.0, [](int c, int) { return c >= 12 ? 7.0 : 0.0; });
  expect("wall from column 0", exactHorizon(wall, 0, 2, rayForAzimuth(wall, 0.0)), std::atan2(7.0, 12.0),
         1e-12);
  expect("wall from column 3", exactHorizon(wall, 3, 2, rayForAzimuth(wall, 0.0)), std::atan2(7.0, 9.0),
         1e-12);
  expect("behind the wall", exactHorizon(wall, 15, 2, rayForAzimuth(wall, kPi)), 0.0, 1e-12);

  // A one-pixel spike seen along its row and along the diagonal, where the bilinear tent
  // is 5 s^2 on the last cell before the spike: steepest at the spike itself.
  const HeightField spike =
      field(21, 21, 1.0, 1.0, [](int c, int r) { return c == 10 && r == 10 ? 5.0 : 0.0; });
  expect("spike along a row", exactHorizon(spike, 2, 10, rayForAzimuth(spike, 0.0)), std::atan2(5.0, 8.0),
         1e-12);
  expect("spike along the diagonal", exactHorizon(spike, 2, 2, rayForAzimuth(spike, 0.25 * kPi)),
         std::atan2(5.0, 8.0 * std::sqrt(2.0)), 1e-12);

  // Nodata (the surface model's rule: a cell with a nodata corner has no surface inside, an edge
  // with a nodata end none along it, a valid grid point is surface; a nodata receiver has no
  // horizon). A saddle cell peaks at 5 in its centre along the diagonal; with one corner nodata
  // the diagonal sees only grid points, all 0. (Along the diagonal the cell's surface is
  // 20 s (1 - s) at s of the cell past 4 diagonal steps, its rise per step 20 s (1 - s) / (4 + s)
  // largest at s^2 + 8 s - 4 = 0.)
  const auto saddle = [&](bool hole) {
    return field(9, 9, 1.0, 1.0, [hole](int c, int r) {
      if (hole && c == 5 && r == 5) return std::numeric_limits<double>::quiet_NaN();
      return (c == 5 && r == 4) || (c == 4 && r == 5) ? 10.0 : 0.0;
    });
  };
  expect(
      "saddle cell along the diagonal",
      exactHorizon(saddle(false), 0, 0, rayForAzimuth(saddle(false), 0.25 * kPi)),
      std::atan2(20.0 * (std::sqrt(20.0) - 4.0) * (5.0 - std::sqrt(20.0)) / std::sqrt(20.0), std::sqrt(2.0)),
      1e-12);
  expect("saddle cell with a nodata corner",
         exactHorizon(saddle(true), 0, 0, rayForAzimuth(saddle(true), 0.25 * kPi)), 0.0, 1e-12);
  // The wall with nodata beside the receiver's row (its cells have no surface, the row's edges
  // do), then with a nodata point at the wall's foot (the ramp's edge gone, the next grid point
  // stands).
  const HeightField beside = field(20, 5, 1.0, 1.0, [](int c, int r) {
    return r == 3 && c > 2 ? std::numeric_limits<double>::quiet_NaN() : c >= 12 ? 7.0 : 0.0;
  });
  expect("wall along a row beside nodata", exactHorizon(beside, 0, 2, rayForAzimuth(beside, 0.0)),
         std::atan2(7.0, 12.0), 1e-12);
  const HeightField foot = field(20, 5, 1.0, 1.0, [](int c, int r) {
    return r == 2 && c == 12 ? std::numeric_limits<double>::quiet_NaN() : c >= 12 ? 7.0 : 0.0;
  });
  expect("wall with a nodata point at its foot", exactHorizon(foot, 0, 2, rayForAzimuth(foot, 0.0)),
         std::atan2(7.0, 13.0), 1e-12);
  // A diagonal of valid grid points between cells with a nodata corner (a survey's footprint
  // clipped at 45 degrees), at the azimuth 2 pi 7 / 8 as the suite computes it: the point 10
  // high two steps along is seen.
  const HeightField clipped = field(9, 9, 1.0, 1.0, [](int c, int r) {
    return c + r < 7 ? std::numeric_limits<double>::quiet_NaN() : c == 2 && r == 5 ? 10.0 : 0.0;
  });
  expect("a diagonal of grid points between nodata cells",
         exactHorizon(clipped, 0, 7, rayForAzimuth(clipped, 2.0 * kPi * 7 / 8)),
         std::atan2(10.0, 2.0 * std::sqrt(2.0)), 1e-12);
  if (!std::isnan(exactHorizon(foot, 12, 2, rayForAzimuth(foot, kPi))))
    failures.push_back("a nodata receiver has a horizon");

  // Random fields: the exact supremum is never below a dense march, and the march converges
  // to it as the step shrinks.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst_coarse = 0.0, worst_fine = 0.0, worst_excess = 0.0;
  for (const auto& [cx, cy] : {std::pair<double, double>{1.0, 1.0}, {1.5, 0.7}}) {
    const HeightField noise = field(33, 29, cx, cy, [&](int, int) { return 10.0 * unit(rng); });
    for (int n = 0; n < 300; ++n) {
      const int c = static_cast<int>(unit(rng) * 33), r = static_cast<int>(unit(rng) * 29);
      const Ray ray = rayForAzimuth(noise, 2.0 * kPi * unit(rng));
      const double exact = exactHorizon(noise, c, r, ray);
      const double coarse = denseHorizon(noise, c, r, ray, 1.0 / 16);
      const double fine = denseHorizon(noise, c, r, ray, 1.0 / 1024);
      worst_coarse = std::max(worst_coarse, exact - coarse);
      worst_fine = std::max(worst_fine, exact - fine);
      worst_excess = std::max(worst_excess, std::max(coarse, fine) - exact);
    }
  }
  const double degrees = 180.0 / kPi;
  if (worst_excess > 1e-12)
    failures.push_back("a dense march exceeded the exact horizon by " +
                       std::to_string(worst_excess * degrees) + " deg");
  // The march misses the near-field slope by O(step) (linear convergence: 64 times smaller
  // at a 64 times finer step), so the fine march must be at least 16 times closer.
  if (!(worst_fine <= worst_coarse / 16.0))
    failures.push_back(
        "the dense march does not converge to the exact horizon: " + std::to_string(worst_coarse * degrees) +
        " deg at step 1/16, " + std::to_string(worst_fine * degrees) + " deg at step 1/1024");
  if (summary) {
    std::ostringstream s;
    s.precision(3);
    s << "exact horizon minus dense march on random 33x29 fields (600 rays): max " << worst_coarse * degrees
      << " deg at step 1/16 px, " << worst_fine * degrees
      << " deg at step 1/1024 px; dense above exact by at most " << worst_excess * degrees
      << " deg; analytic plane/wall/spike/nodata cases within 1e-12 rad";
    *summary = s.str();
  }
  return failures;
}

}  // namespace hfvis::bench
