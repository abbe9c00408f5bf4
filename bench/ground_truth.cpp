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

double heightAt(const HeightField& f, int col, int row) {
  return static_cast<double>(f.heights[static_cast<std::size_t>(row) * f.width + col]) * f.z_scale;
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

std::vector<std::int32_t> chooseReceivers(const HeightField& f, int count) {
  const std::size_t pixels = f.pixelCount();
  std::vector<std::int32_t> chosen;
  if (count <= 0 || static_cast<std::size_t>(count) >= pixels) {
    for (std::size_t p = 0; p < pixels; ++p) chosen.push_back(static_cast<std::int32_t>(p));
    return chosen;
  }
  std::mt19937_64 rng(20240003);
  std::uniform_int_distribution<std::size_t> pick(0, pixels - 1);
  std::vector<bool> taken(pixels, false);
  while (chosen.size() < static_cast<std::size_t>(count)) {
    const std::size_t p = pick(rng);
    if (!taken[p]) taken[p] = true, chosen.push_back(static_cast<std::int32_t>(p));
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
  const double t_end = exitDistance(f, c, r, ray);
  if (!(t_end > 0.0)) return -0.5 * kPi;
  const double ax = std::abs(ray.dx), ay = std::abs(ray.dy);
  const double h0 = heightAt(f, c, r);
  double best = -kInf;  // steepest rise per unit t so far
  double t0 = 0.0;
  // The receiver is a grid point, so the ray crosses column lines at t = k / |dx| and row
  // lines at t = m / |dy|; between consecutive crossings it stays in one cell.
  long kx = 1, ky = 1;
  while (t0 < t_end) {
    const double nx = ax > 0.0 ? kx / ax : kInf, ny = ay > 0.0 ? ky / ay : kInf;
    const double t1 = std::min({nx, ny, t_end});
    if (nx <= t1) ++kx;
    if (ny <= t1) ++ky;
    const double tm = 0.5 * (t0 + t1);
    const int i = std::clamp(static_cast<int>(std::floor(c + tm * ray.dx)), 0, f.width - 2);
    const int j = std::clamp(static_cast<int>(std::floor(r + tm * ray.dy)), 0, f.height - 2);
    const double h00 = heightAt(f, i, j), h10 = heightAt(f, i + 1, j);
    const double h01 = heightAt(f, i, j + 1), h11 = heightAt(f, i + 1, j + 1);
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
    t0 = t1;
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
  if (field.nodataCount() > 0) throw InvalidArgument("ground truth does not handle nodata heights");
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
      << " deg; analytic plane/wall/spike cases within 1e-12 rad";
    *summary = s.str();
  }
  return failures;
}

}  // namespace hfvis::bench
