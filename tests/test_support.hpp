// test_support.hpp: what the kernel tests share: one device context, comparisons that
// report where they fail, and the sizes every operation is tried on.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis_testing/synthetic_fields.hpp"

namespace hfvis::testing {

// A fresh, empty directory for the running test: HFVIS_TEST_TMP_DIR/<area>/<test>_<pid>. One per
// test and process, so CTest's parallel processes and two build trees' runs never share one, and
// what a failed test leaves stays there to look at.
inline std::filesystem::path freshTestDirectory(const std::string& area) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir = std::filesystem::path(HFVIS_TEST_TMP_DIR) / area /
                                    (std::string(info->name()) + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// A context on the device every test runs on (HFVIS_DEVICE, else automatic: the HFVIS_*
// variables as ContextOptions::fromEnvironment reads them), in `layout` (Automatic: the
// environment's or the device's), created once per layout.
inline const ComputeContext& testContext(LineLayout layout = LineLayout::Automatic) {
  static std::map<LineLayout, ComputeContext> contexts;
  auto it = contexts.find(layout);
  if (it == contexts.end()) {
    ContextOptions options = ContextOptions::fromEnvironment();
    if (layout != LineLayout::Automatic) options.line_layout = layout;
    it = contexts.emplace(layout, ComputeContext::create(options)).first;
  }
  return it->second;
}

// Runs `body(context)` with a context in each line-buffer layout: line-major (the CPU
// default; the horizon sweep in SIMD lanes), then step-major (the GPU default; one line per
// work-item). CI has no GPU, so the GPU layout is tested here.
template <typename Body>
void forEachLayout(Body&& body) {
  for (LineLayout layout : {LineLayout::LineMajor, LineLayout::StepMajor}) {
    SCOPED_TRACE(layout == LineLayout::LineMajor ? "line-major layout" : "step-major layout");
    body(testContext(layout));
  }
}

// Kernel-against-reference tolerance for values of order one computed through a division:
// none where the device divides correctly rounded (as C++ does), else a few ulp.
inline float divisionTolerance() { return testContext().device().correctly_rounded_divide ? 0.0f : 2e-6f; }

// The w x h points of f from (x0, y0), with f's cell size and z-scale.
inline HeightField cropField(const HeightField& f, int x0, int y0, int w, int h) {
  HeightField out = f;
  out.width = w;
  out.height = h;
  out.heights.resize(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) out.heights[static_cast<std::size_t>(y) * w + x] = f.at(x0 + x, y0 + y);
  return out;
}

// Awkward sizes (CLBlast style): 1x1, 1xN, Nx1, odd, non-square.
inline const std::vector<std::pair<int, int>>& awkwardSizes() {
  static const std::vector<std::pair<int, int>> sizes = {{1, 1}, {1, 9}, {9, 1}, {7, 13}, {33, 20}, {40, 41}};
  return sizes;
}

// Runs `body(name, field)` on every hard case (synthetic_fields.hpp) at every awkward size,
// with cells 1.5 wide (so x and y differ), the case and size named in any failure.
template <typename Body>
void forEachHardCase(Body&& body) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h));
      HeightField field = makeSyntheticField(name, w, h, 3);
      field.cell_size_x = 1.5;
      body(name, field);
    }
  }
}

// A street canyon: ground at 0 in the columns within half_width - 1 of the centre column
// width / 2, walls of height `depth` on both sides out to the field's edges (flat roofs), so a
// receiver on the centre column sees the walls' top edges half_width pixels away across the
// street and nothing along it. Closed-form horizons in the axis and diagonal directions.
inline HeightField streetCanyon(int width, int height, int half_width, float depth) {
  HeightField field;
  field.width = width;
  field.height = height;
  field.heights.assign(static_cast<std::size_t>(width) * height, 0.0f);
  for (int row = 0; row < height; ++row)
    for (int c = 0; c < width; ++c)
      if (std::abs(c - width / 2) >= half_width) field.heights[static_cast<std::size_t>(row) * width + c] = depth;
  return field;
}

// Element-wise comparison: NaN must match NaN, otherwise |a - b| <= tolerance. Reports the
// first few mismatches with their index.
inline ::testing::AssertionResult nearlyEqual(const std::vector<float>& actual,
                                              const std::vector<float>& expected, float tolerance) {
  if (actual.size() != expected.size())
    return ::testing::AssertionFailure() << "sizes differ: " << actual.size() << " vs " << expected.size();
  int failures = 0;
  std::string report;
  for (std::size_t i = 0; i < actual.size(); ++i) {
    const float a = actual[i], e = expected[i];
    const bool ok = (std::isnan(a) && std::isnan(e)) ||
                    (!std::isnan(a) && !std::isnan(e) && std::abs(a - e) <= tolerance);
    if (!ok && failures++ < 5)
      report += "\n  [" + std::to_string(i) + "] " + std::to_string(a) + " vs " + std::to_string(e);
  }
  if (failures == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << failures << " of " << actual.size()
                                       << " values differ by more than " << tolerance << ":" << report;
}

inline HeightField fieldFrom(int width, int height, std::vector<float> heights) {
  HeightField f;
  f.width = width;
  f.height = height;
  f.heights = std::move(heights);
  return f;
}

// Surfaces whose sight lines between two of their points graze them everywhere (the viewshed's and
// region visibility's tie rule under the heights' rounding): tilted planes at 8848, near 0 and
// steep, and at 3e5, and a bowl, whose chords run above it.
struct GrazingSurface {
  const char* name;
  double base, along_x, along_y, bowl;
};
inline std::vector<GrazingSurface> grazingSurfaces() {
  return {{"gentle at 8848", 8848.0, 0.001, 0.0, 0.0},
          {"steep", 0.0, 0.37, 0.11, 0.0},
          {"at 3e5", 3e5, 1.7, -0.9, 0.0},
          {"bowl", 100.0, 0.0, 0.0, 0.013}};
}
// Planes that cross 0 far from the field's corner (at column 200; fields at least 216 wide): their
// heights near 0 round little, the positions there by units in the last place of 200.
inline std::vector<GrazingSurface> planesCrossingZeroFarFromTheCorner() {
  return {{"column - 200", -200.0, 1.0, 0.0, 0.0}, {"0.7 column + 0.3 row - 146", -146.0, 0.7, 0.3, 0.0}};
}
// Its float32 heights over width x height pixels (the bowl's bottom at the middle).
inline std::vector<float> grazingHeights(const GrazingSurface& s, int width, int height) {
  std::vector<float> heights(static_cast<std::size_t>(width) * height);
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) {
      const double x = col - width / 2, y = row - height / 2;
      heights[static_cast<std::size_t>(row) * width + col] =
          static_cast<float>(s.base + s.along_x * col + s.along_y * row + s.bowl * (x * x + y * y));
    }
  return heights;
}

// Heights of long random lines, width * height values by kind: 0 tie-rich small integers
// 0..3, 1 a smooth random walk (steps in [-1, 1]), 2 float noise in [0, noise_range), 3 two
// levels 0.5 apart at 1000 (ties at a large offset).
inline std::vector<float> randomLineHeights(int kind, int width, int height, float noise_range,
                                            std::mt19937& rng) {
  std::vector<float> heights(static_cast<std::size_t>(width) * height);
  float walk = 0.0f;
  for (auto& v : heights) {
    if (kind == 0) v = float(std::uniform_int_distribution<int>(0, 3)(rng));
    if (kind == 1) v = walk += std::uniform_real_distribution<float>(-1.0f, 1.0f)(rng);
    if (kind == 2) v = std::uniform_real_distribution<float>(0.0f, noise_range)(rng);
    if (kind == 3) v = float(std::uniform_int_distribution<int>(0, 1)(rng)) * 0.5f + 1000.0f;
  }
  return heights;
}

// Per-row spacing as a latitude / longitude grid has it, exaggerated: along columns from 1.5 at
// the top to 0.75 at the bottom, along rows slowly growing; the field's cell sizes the centre
// row's.
inline void setRowSpacing(HeightField& field) {
  field.row_cell_size_x.clear();
  field.row_cell_size_y.clear();
  for (int r = 0; r < field.height; ++r) {
    const double t = field.height > 1 ? double(r) / (field.height - 1) : 0.0;
    field.row_cell_size_x.push_back(1.5 * (1.0 - 0.5 * t));
    field.row_cell_size_y.push_back(1.0 + 0.02 * t);
  }
  field.cell_size_x = field.row_cell_size_x[field.height / 2];
  field.cell_size_y = field.row_cell_size_y[field.height / 2];
}

}  // namespace hfvis::testing
