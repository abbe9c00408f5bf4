// bench/suite_support.cpp: see suite_support.hpp.
#include "suite_support.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <thread>

#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis_testing/synthetic_fields.hpp"

namespace hfvis::bench {

namespace fs = std::filesystem;

std::string num(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

namespace {

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return quoted + "\"";
}

}  // namespace

CsvWriter::CsvWriter(const std::string& path, std::vector<std::string> columns)
    : out_(path), columns_(std::move(columns)) {
  if (!out_) throw IoError(path, "cannot write");
  for (std::size_t i = 0; i < columns_.size(); ++i) out_ << (i ? "," : "") << columns_[i];
  out_ << "\n";
}

void CsvWriter::write(const Row& row) {
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    const auto it = row.find(columns_[i]);
    out_ << (i ? "," : "") << (it == row.end() ? "" : csvField(it->second));
  }
  out_ << "\n";
  out_.flush();
}

HeightField crop(const HeightField& field, int width, int height) {
  HeightField c = field;
  c.width = std::min(width, field.width);
  c.height = std::min(height, field.height);
  c.heights.clear();
  for (int r = 0; r < c.height; ++r)
    for (int col = 0; col < c.width; ++col) c.heights.push_back(field.at(col, r));
  return c;
}

namespace {

// A city DSM as surveys deliver it (the "city_holes" content): the city with nodata where the
// sensor saw nothing: a void (a lake, a glass roof: an ellipse), the survey's footprint clipped
// across one corner, and dropouts of 1 - 3 x 1 - 3 pixels, mostly at the foot of walls (the
// shadows of tall buildings; about 1.5 % of the field, all the holes about 6 %). Fixed seed.
void punchHoles(HeightField& f) {
  const int w = f.width, h = f.height;
  const float nodata = std::numeric_limits<float>::quiet_NaN();
  auto at = [&](int c, int r) -> float& { return f.heights[static_cast<std::size_t>(r) * w + c]; };
  const double cx = 0.68 * w, cy = 0.3 * h, rx = 0.1 * w + 1.0, ry = 0.07 * h + 1.0;
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      if ((c - cx) * (c - cx) / (rx * rx) + (r - cy) * (r - cy) / (ry * ry) <= 1.0 || c + r < (w + h) / 10)
        at(c, r) = nodata;
  // Beside a step of more than 2 (a wall's foot or top).
  auto at_wall = [&](int c, int r) {
    for (const auto& [dc, dr] : {std::pair<int, int>{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      const int nc = c + dc, nr = r + dr;
      if (nc >= 0 && nr >= 0 && nc < w && nr < h && std::fabs(at(nc, nr) - at(c, r)) > 2.0f) return true;
    }
    return false;
  };
  std::mt19937 rng(29);
  std::uniform_int_distribution<int> col(0, w - 1), row(0, h - 1), side(1, 3);
  for (int n = 0; n < w * h / 300; ++n) {
    int c = col(rng), r = row(rng);
    for (int tries = 0; tries < 8 && !at_wall(c, r); ++tries) c = col(rng), r = row(rng);
    const int sw = side(rng), sh = side(rng);
    for (int y = r; y < std::min(h, r + sh); ++y)
      for (int x = c; x < std::min(w, c + sw); ++x) at(x, y) = nodata;
  }
}

}  // namespace

Content loadContent(const SuiteOptions& options, const std::string& name, int n) {
  Content c;
  c.name = name;
  const bool city = name == "city_dsm" || name == "city_holes";
  if (options.mode == "tiny") {
    // Odd, non-square sizes; the "dome" stands in for the DEM with non-square cells.
    if (name == "dem") {
      c.field = makeSyntheticField("dome", n + 5, n - 1, 3);
      c.field.cell_size_x = 1.5, c.field.cell_size_y = 0.75;
    } else {
      c.field = makeSyntheticField(name == "fractal" ? "noise" : city ? "city" : name, n, n - 3, 3);
    }
  } else if (city) {
    // The city DSM hard case (testing's synthetic "city"): one-pixel streets and walls, roofs
    // touching at corners, courtyards, towers, an axis grid and a rotated one, generated here.
    c.field = makeSyntheticField("city", n, n, 1);
  } else if (name == "dem") {
    // The central n x n of the DEM (all of it when smaller), so that every content of the
    // speed/error plane has the same size.
    const HeightField dem = readHeightField(options.dem_path);
    const int w = std::min(n, dem.width), h = std::min(n, dem.height);
    const int c0 = (dem.width - w) / 2, r0 = (dem.height - h) / 2;
    c.field = dem;
    c.field.width = w, c.field.height = h;
    c.field.heights.clear();
    for (int r = r0; r < r0 + h; ++r)
      for (int col = c0; col < c0 + w; ++col) c.field.heights.push_back(dem.at(col, r));
  } else {
    c.field =
        readHeightField((fs::path(options.data_dir) / (name + "_" + std::to_string(n) + ".exr")).string());
  }
  if (name == "city_holes") punchHoles(c.field);
  c.label = name + "_" + std::to_string(c.field.width) + "x" + std::to_string(c.field.height);
  return c;
}

Timing timeWithWarmUp(const std::function<void()>& warm_up, const std::function<void()>& run,
                      const TimingPolicy& policy) {
  warm_up();
  Timing timing;
  const Timing first = timeRepeated(run, {1, 1, 0.0});
  TimingPolicy rest = policy;
  if (first.min() >= 1.0) {  // expensive: the small run was warm-up enough, this one counts
    timing = first;
    rest.min_reps = std::max(0, policy.min_reps - 1);
    rest.max_reps = std::max(0, policy.max_reps - 1);
    rest.budget_seconds = policy.budget_seconds - first.min();
  }
  const Timing more = timeRepeated(run, rest);
  timing.seconds.insert(timing.seconds.end(), more.seconds.begin(), more.seconds.end());
  timing.cpu_seconds.insert(timing.cpu_seconds.end(), more.cpu_seconds.begin(), more.cpu_seconds.end());
  return timing;
}

int threads() { return std::max(1u, std::thread::hardware_concurrency()); }

void say(const char* format, ...) {
  static const auto start = std::chrono::steady_clock::now();
  std::fprintf(stdout, "%7.1fs ", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  va_list args;
  va_start(args, format);
  std::vfprintf(stdout, format, args);
  va_end(args);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

}  // namespace hfvis::bench
