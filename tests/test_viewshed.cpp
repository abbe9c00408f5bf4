// test_viewshed.cpp: the viewshed kernels against brute force in double (hfvis/
// viewshed_reference.hpp) on rough terrain and the hard cases, for valley, ridge, plateau,
// high and border observers, in both layouts; curvature against its closed form; cumulative
// viewsheds against the sum of single ones; bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/sweep_options.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "hfvis/viewshed.hpp"
#include "hfvis_testing/viewshed_reference.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::forEachLayout;
using testing::testContext;

HeightField roughTerrain(int w = 97, int h = 83) {
  static const HeightField fractal = readHeightField(std::string(HFVIS_DATA_DIR) + "/fractal_256.exr");
  return testing::cropField(fractal, 40, 60, w, h);
}

// Where the field is lowest, highest (ridge / peak) and at its middle.
Observer lowest(const HeightField& f, double height) {
  const auto it = std::min_element(f.heights.begin(), f.heights.end(),
                                   [](float a, float b) { return std::isfinite(a) && (!std::isfinite(b) || a < b); });
  const int p = static_cast<int>(it - f.heights.begin());
  return {p % f.width, p / f.width, height};
}
Observer highest(const HeightField& f, double height) {
  const auto it = std::max_element(f.heights.begin(), f.heights.end(),
                                   [](float a, float b) { return !std::isfinite(a) || (std::isfinite(b) && a < b); });
  const int p = static_cast<int>(it - f.heights.begin());
  return {p % f.width, p / f.width, height};
}

struct Agreement {
  std::size_t targets = 0, visible = 0, mismatches = 0, grazing = 0, marched = 0;
};

// The device's viewshed against brute force. A disagreement is allowed only where the sight
// line grazes, the surface strictly between eye and target coming within `graze` of it
// (SightLine::interior_rise), and on at most 1 % of the targets. Returns the counts.
Agreement compare(const ComputeContext& context, const HeightField& field, const Observer& o,
                  const ViewshedOptions& options, double graze) {
  const ViewshedResult want = referenceViewshed(field, o, options);
  ViewshedOutputs outputs;
  outputs.angle = true;
  const ViewshedResult got = computeViewshed(context, field, o, options, outputs);
  Agreement a;
  a.marched = got.marched;
  for (std::size_t p = 0; p < want.visible.size(); ++p) {
    if (std::isnan(want.visible[p])) {
      EXPECT_TRUE(std::isnan(got.visible[p])) << "nodata at " << p;
      continue;
    }
    ++a.targets;
    a.visible += want.visible[p] == 1.0f;
    EXPECT_NEAR(got.angle[p], want.angle[p], 2e-6 * (1.0 + std::fabs(want.angle[p]))) << "angle at " << p;
    if (got.visible[p] == want.visible[p]) continue;
    ++a.mismatches;
    const int col = static_cast<int>(p % field.width), row = static_cast<int>(p / field.width);
    const double clearance = referenceSightLine(field, o, options, col, row).interior_rise;
    if (std::fabs(clearance) <= graze)
      ++a.grazing;
    else
      ADD_FAILURE() << "target " << col << "," << row << ": device " << got.visible[p] << ", brute force "
                    << want.visible[p] << ", the surface " << clearance << " above the sight line at most";
  }
  EXPECT_LE(a.grazing, a.targets / 100) << a.grazing << " grazing disagreements of " << a.targets;
  return a;
}

TEST(Viewshed, RoughTerrainMatchesBruteForce) {
  const HeightField f = roughTerrain();
  forEachLayout([&](const ComputeContext& context) {
    const std::vector<std::pair<std::string, Observer>> observers = {
        {"valley", lowest(f, 2.0)},      {"ridge", highest(f, 2.0)},          {"middle", {48, 41, 2.0}},
        {"high", {48, 41, 60.0}},        {"ground", {30, 50, 0.0}},           {"corner", {0, 0, 2.0}},
        {"border", {96, 40, 5.0}},       {"bottom edge", {50, 82, 1.0}},
    };
    std::size_t visible = 0, targets = 0, grazing = 0;
    for (const auto& [name, o] : observers) {
      SCOPED_TRACE(name);
      ViewshedOptions options;
      const Agreement a = compare(context, f, o, options, 1e-4);
      visible += a.visible, targets += a.targets, grazing += a.grazing;
      // The rays' bounds settle most targets (observers near the middle: rays are marched).
      // The rays' bounds settle a good share of the hidden targets (the visible ones are all marched).
      if (a.targets - a.visible > 1000) {
        EXPECT_LT(a.marched - a.visible, (a.targets - a.visible) * 3 / 4) << a.marched << " marched";
      }
    }
    // Both answers occur often, and grazing disagreements stay rare.
    EXPECT_GT(visible, targets / 10);
    EXPECT_LT(visible, targets * 9 / 10);
    EXPECT_LE(grazing, targets / 2000) << grazing << " grazing of " << targets;
    std::printf("rough terrain: %zu targets, %zu visible, %zu grazing disagreements\n", targets, visible, grazing);
  });
}

TEST(Viewshed, NeededHeightMatchesBruteForce) {
  const HeightField f = roughTerrain();
  for (const Observer& o : {Observer{48, 41, 2.0}, Observer{10, 70, 0.5}}) {
    ViewshedOptions options;
    options.target_height = 0.5;
    const ViewshedResult want = referenceViewshed(f, o, options);
    ViewshedOutputs outputs;
    outputs.needed_height = true;
    forEachLayout([&](const ComputeContext& context) {
      const ViewshedResult got = computeViewshed(context, f, o, options, outputs);
      std::size_t positive = 0;
      for (std::size_t p = 0; p < want.needed_height.size(); ++p) {
        ASSERT_NEAR(got.needed_height[p], want.needed_height[p], 1e-3 + 1e-4 * want.needed_height[p]) << "at " << p;
        positive += want.needed_height[p] > 0.5;
        // Seen exactly where the target's own height is enough.
        if (std::fabs(want.needed_height[p] - 0.5) > 1e-3) {
          EXPECT_EQ(want.visible[p] == 1.0f, want.needed_height[p] <= 0.5) << "at " << p;
        }
      }
      EXPECT_GT(positive, want.needed_height.size() / 10);
    });
  }
}

TEST(Viewshed, EveryTargetMarchedAgrees) {
  // The rays' bounds only skip marches: marching every target gives the same visible set.
  const HeightField f = roughTerrain(120, 110);
  const Observer o{60, 55, 3.0};
  ViewshedOptions fast, marched;
  marched.march_every_target = true;
  const ViewshedResult a = computeViewshed(testContext(), f, o, fast);
  const ViewshedResult b = computeViewshed(testContext(), f, o, marched);
  std::size_t differ = 0;
  for (std::size_t p = 0; p < a.visible.size(); ++p) differ += a.visible[p] != b.visible[p];
  EXPECT_LE(differ, a.visible.size() / 5000);
}

TEST(Viewshed, HardCasesMatchBruteForce) {
  forEachLayout([&](const ComputeContext& context) {
    for (const std::string& name : syntheticFieldNames()) {
      SCOPED_TRACE(name);
      const HeightField f = makeSyntheticField(name, 61, 53);
      Observer o{30, 26, 1.5};
      if (!std::isfinite(f.at(o.col, o.row))) o = lowest(f, 1.5);
      // Heights of order 1e6 (the cliff) round at about 0.1 in single precision.
      double scale = 1.0;
      for (float v : f.heights)
        if (std::isfinite(v)) scale = std::max(scale, std::fabs(static_cast<double>(v)));
      const Agreement a = compare(context, f, o, {}, 1e-5 * scale);
      EXPECT_LE(a.grazing, a.targets / 100);
    }
  });
}

TEST(Viewshed, OptionsMatchBruteForce) {
  const HeightField f = roughTerrain();
  const Observer o{48, 41, 2.0};
  forEachLayout([&](const ComputeContext& context) {
    ViewshedOptions options;
    options.max_distance = 30.5;
    options.target_height = 1.5;
    SCOPED_TRACE("maximum distance, target height");
    compare(context, f, o, options, 1e-4);
    options = {};
    options.azimuth_from_deg = 300.0;  // across north
    options.azimuth_to_deg = 45.0;
    options.elevation_min_deg = -10.0;
    options.elevation_max_deg = 5.0;
    SCOPED_TRACE("field of view");
    const Agreement a = compare(context, f, o, options, 1e-4);
    EXPECT_GT(a.visible, 0u);
    options = {};
    options.absolute = true;
    HeightField anisotropic = f;
    anisotropic.cell_size_x = 2.0;
    anisotropic.cell_size_y = 0.5;
    anisotropic.z_scale = 0.3;
    options.curvature = 0.01;
    SCOPED_TRACE("anisotropic cells, absolute eye, curvature");
    compare(context, anisotropic, {10, 70, 40.0}, options, 1e-4);
    {
      // Every sight line marched whole through the maximum pyramid: its rounding fallback near
      // the target (a pixel's step that once rounded short of t = 1) is met here.
      SCOPED_TRACE("the same, every target marched");
      ViewshedOptions m = options;
      m.march_every_target = true;
      compare(context, anisotropic, {10, 70, 40.0}, m, 1e-4);
    }
    // A negative drop (refraction beyond 1) raises far terrain, for the pyramid's skips too.
    options = {};
    options.curvature = -0.004;
    SCOPED_TRACE("negative curvature");
    compare(context, f, o, options, 1e-4);
    options.march_every_target = true;
    compare(context, f, o, options, 1e-4);
    // A budget that just holds the rays' upper bounds (a float per point, half the budget).
    options = {};
    options.memory_budget_bytes = 2 * sizeof(float) * f.pixelCount();
    compare(context, f, o, options, 1e-4);
  });
  // Azimuths 0 and 360 are the whole circle.
  ViewshedOptions circle;
  circle.azimuth_to_deg = 360.0;
  EXPECT_EQ(computeViewshed(testContext(), f, o, circle).visible, computeViewshed(testContext(), f, o, {}).visible);
  // A budget that leaves no room for the rays' bounds: every target is marched.
  ViewshedOptions tiny;
  tiny.memory_budget_bytes = 16;
  EXPECT_EQ(computeViewshed(testContext(), f, o, tiny).visible, computeViewshed(testContext(), f, o, {}).visible);
}

// The eye o sees every point of the field and needs no height for any, by the double-precision
// reference and the kernels, with and without the rays, in both layouts.
void expectEyeSeesAll(const HeightField& field, const Observer& o) {
  const long all = long(field.pixelCount());
  ViewshedOutputs outputs;
  outputs.needed_height = true;
  for (const bool every : {false, true}) {
    ViewshedOptions options;
    options.target_height = 0.0;
    options.march_every_target = every;
    const ViewshedResult want = referenceViewshed(field, o, options);
    EXPECT_EQ(std::count(want.visible.begin(), want.visible.end(), 1.0f), all);
    forEachLayout([&](const ComputeContext& context) {
      const ViewshedResult got = computeViewshed(context, field, o, options, outputs);
      EXPECT_EQ(std::count(got.visible.begin(), got.visible.end(), 1.0f), all);
      EXPECT_EQ(std::count(got.needed_height.begin(), got.needed_height.end(), 0.0f), all);
    });
  }
}

TEST(Viewshed, ATiltedPlaneSeesItselfWhereverItLies) {
  // An eye on a tilted plane sees every point of it (the tie rule: grazing sees, as on flat
  // ground), though the float32 heights and the march's values round a hair above or below the
  // sight lines; an exact sign hid nearly every target on the plane at 8848, and about 500 of a
  // bowl's, whose chords run above it. The needed height is 0 there. A wall of 2 cm across the
  // plane at 8848 (about 20 units in the last place there) still hides what lies behind it.
  const int w = 97, h = 71;
  for (const testing::GrazingSurface& surface : testing::grazingSurfaces()) {
    SCOPED_TRACE(surface.name);
    const std::vector<float> heights = testing::grazingHeights(surface, w, h);
    for (const Observer& o : {Observer{48, 35, 0.0}, Observer{3, 66, 0.0}}) {
      expectEyeSeesAll(testing::fieldFrom(w, h, heights), o);
      if (surface.base != 8848.0) continue;
      std::vector<float> walled = heights;
      for (int row = 0; row < h; ++row) walled[row * w + 60] += 0.02f;
      const HeightField wall = testing::fieldFrom(w, h, walled);
      forEachLayout([&](const ComputeContext& context) {
        const ViewshedResult got = computeViewshed(context, wall, {48, 35, 0.0}, {});
        for (int row = 0; row < h; ++row) EXPECT_EQ(got.visible[row * w + 80], 0.0f) << row;
      });
    }
  }
}

TEST(Viewshed, APlaneCrossingZeroFarFromTheCornerSeesItself) {
  // Where a plane crosses 0 far from the field's corner its heights there are near 0, and so is the
  // rounding forgiven, but a march begun inside a cell (past what the rays or the culling settled)
  // evaluated the surface at the absolute position, which rounds by units in the last place of the
  // column: from column 200 on h = column - 200, 6970 of 65536 targets were hidden (the region
  // probe's plane). The position is now taken from the eye's grid point.
  for (const testing::GrazingSurface& surface : testing::planesCrossingZeroFarFromTheCorner()) {
    const HeightField field = testing::fieldFrom(216, 40, testing::grazingHeights(surface, 216, 40));
    for (const Observer& o : {Observer{200, 0, 0.0}, Observer{201, 39, 0.0}, Observer{150, 20, 0.0}}) {
      SCOPED_TRACE(std::string(surface.name) + " from " + std::to_string(o.col) + "," +
                   std::to_string(o.row));
      expectEyeSeesAll(field, o);
    }
  }
}

TEST(Viewshed, APlaneCrossingZeroBetweenEyeAndTargetSeesItself) {
  // Seen from its 0 at height 0, an exact plane (heights multiples of 1/8) steep across the sight
  // lines: the ends' heights are near 0, and so was the rounding forgiven, while the surface at the
  // crossings is interpolated from corners of a few units, which round by more: 7 of 369 targets
  // were hidden (a probe's find). A cell's corners now bound what its stretch forgives.
  for (const auto& [w, h, sx, sy, eye] : {std::tuple{41, 9, 0.375, 1.25, Observer{20, 4, 0.0}},
                                          std::tuple{101, 9, 0.5, 3.0, Observer{50, 4, 0.0}},
                                          std::tuple{101, 9, 0.5, 3.0, Observer{49, 4, 0.0}},
                                          std::tuple{101, 9, 2.0, 0.5, Observer{50, 4, 0.0}}}) {
    std::vector<float> heights(std::size_t(w) * h);
    for (int row = 0; row < h; ++row)
      for (int col = 0; col < w; ++col)
        heights[std::size_t(row) * w + col] = float(sx * (col - eye.col) + sy * (row - eye.row));
    SCOPED_TRACE(std::to_string(sx) + " x + " + std::to_string(sy) + " y from " + std::to_string(eye.col));
    expectEyeSeesAll(testing::fieldFrom(w, h, heights), eye);
  }
}

TEST(Viewshed, NeededHeightKeepsToTheGeometryFarFromZero) {
  // The needed height is the exact one: the city of whole-number heights raised by 8848 (exactly,
  // in float32) needs what it needs at 0 to within the rounding of its values. Taken with the
  // rounding the visibility forgives, a roof near the eye lowered far targets' needs by it times
  // the ratio of their distances (0.3 of 43.8 at 8848).
  const HeightField city = makeSyntheticField("city", 64, 64);
  HeightField raised = city;
  for (float& v : raised.heights) v += 8848.0f;
  ViewshedOptions options;
  ViewshedOutputs outputs;
  outputs.needed_height = true;
  const Observer o{32, 32, 1.5};
  const ViewshedResult low = computeViewshed(testContext(), city, o, options, outputs);
  const ViewshedResult high = computeViewshed(testContext(), raised, o, options, outputs);
  // (A need within the rounding forgiven at 8848 is 0 there: a target on the surface is seen.)
  double most = 0.0, most_zeroed = 0.0;
  for (std::size_t p = 0; p < low.needed_height.size(); ++p) {
    const double a = low.needed_height[p], b = high.needed_height[p];
    if (b == 0.0 && a > 0.0)
      most_zeroed = std::max(most_zeroed, a);
    else
      most = std::max(most, std::fabs(a - b));
  }
  EXPECT_LT(most, 0.02);
  EXPECT_LT(most_zeroed, 0.02);
  std::printf("largest difference %.4f, largest need zeroed at 8848 %.4f\n", most, most_zeroed);
}

TEST(Viewshed, CurvatureHidesFlatGroundBeyondTheHorizon) {
  // Flat ground, an eye h above it, targets on the ground: visible out to sqrt(2 R h / (1 - K)).
  HeightField f;
  f.width = 3000;
  f.height = 3;
  f.cell_size_x = f.cell_size_y = 10.0;
  f.heights.assign(static_cast<std::size_t>(f.width) * f.height, 100.0f);
  const double eye = 10.0, refraction = 0.13;
  ViewshedOptions options;
  options.curvature = earthCurvature(refraction);
  const ViewshedResult r = computeViewshed(testContext(), f, {0, 1, eye}, options);
  int farthest = 0;
  for (int x = 0; x < f.width; ++x)
    if (r.visible[f.width + x] == 1.0f) farthest = x;
  const double expected = std::sqrt(2.0 * kEarthRadius * eye / (1.0 - refraction));
  // A target d beyond the horizon is hidden by the ground rising c d^2 above its sight line; the
  // march forgives the heights' rounding, 2^-21 of the eye's and the target's heights and the
  // drop (about 1e-4 here), so it sees up to sqrt(that / c) farther (about 39 m).
  const double forgiven = std::ldexp(2.0 * (100.0 + eye), -21);
  EXPECT_GE(farthest * f.cell_size_x, expected - f.cell_size_x);
  EXPECT_LE(farthest * f.cell_size_x, expected + std::sqrt(forgiven / options.curvature) + f.cell_size_x)
      << "expected " << expected;
  EXPECT_LT(farthest, f.width - 1);
}

TEST(Viewshed, CumulativeCountsTheObservers) {
  HeightField f = roughTerrain(70, 64);
  f.heights[5 * 70 + 9] = NAN;
  const std::vector<Observer> observers = {{3, 3, 2.0}, {35, 30, 2.0}, {69, 63, 10.0}, {35, 30, 2.0}};
  ViewshedOptions options;
  int calls = 0;
  options.progress = [&](int done, int total) {
    ++calls;
    EXPECT_EQ(total, 4);
    EXPECT_EQ(done, calls);
  };
  const CumulativeViewshed c = computeCumulativeViewshed(testContext(), f, observers, options);
  EXPECT_EQ(calls, 4);
  std::vector<float> sum(f.pixelCount(), 0.0f);
  for (const Observer& o : observers) {
    const ViewshedResult r = computeViewshed(testContext(), f, o, {});
    for (std::size_t p = 0; p < sum.size(); ++p) sum[p] += r.visible[p];
  }
  for (std::size_t p = 0; p < sum.size(); ++p) {
    if (std::isnan(sum[p])) {
      EXPECT_TRUE(std::isnan(c.count[p]));
      continue;
    }
    ASSERT_EQ(c.count[p], sum[p]) << "at " << p;
  }
  for (const Observer& o : observers) EXPECT_GE(c.count[o.row * 70 + o.col], 1.0f);  // each sees its own point
}

TEST(Viewshed, AwkwardSizes) {
  for (const auto& [w, h] : testing::awkwardSizes()) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    const HeightField f = makeSyntheticField("noise", w, h);
    compare(testContext(), f, {w / 2, h / 2, 0.5}, {}, 1e-4);
  }
}

TEST(Viewshed, BadInputIsRefused) {
  HeightField f = makeSyntheticField("sine", 20, 10);
  f.heights[3 * 20 + 4] = NAN;
  const ComputeContext& c = testContext();
  EXPECT_THROW(computeViewshed(c, f, {20, 0, 2.0}, {}), InvalidArgument);
  EXPECT_THROW(computeViewshed(c, f, {-1, 0, 2.0}, {}), InvalidArgument);
  EXPECT_THROW(computeViewshed(c, f, {4, 3, 2.0}, {}), InvalidArgument);
  EXPECT_THROW(computeViewshed(c, f, {1, 1, NAN}, {}), InvalidArgument);
  // (an eye 1e39 below the surface saw every target: a probe's find; the CLI's range)
  for (const double height : {-1e39, 1e300, -1.1e12})
    EXPECT_THROW(computeViewshed(c, f, {1, 1, height}, {}), InvalidArgument) << height;
  EXPECT_NO_THROW(computeViewshed(c, f, {1, 1, -1e12}, {}));
  ViewshedOptions o;
  o.target_height = -1.0;
  EXPECT_THROW(computeViewshed(c, f, {1, 1, 2.0}, o), InvalidArgument);
  o = {};
  o.max_distance = NAN;
  EXPECT_THROW(computeViewshed(c, f, {1, 1, 2.0}, o), InvalidArgument);
  o = {};
  o.azimuth_to_deg = 400.0;
  EXPECT_THROW(computeViewshed(c, f, {1, 1, 2.0}, o), InvalidArgument);
  o = {};
  o.elevation_min_deg = 10.0;
  o.elevation_max_deg = 0.0;
  EXPECT_THROW(computeViewshed(c, f, {1, 1, 2.0}, o), InvalidArgument);
  // The sweep's curvature rule: within -1 .. 1 per ground unit (far beyond, the drops overflowed
  // float and the viewshed saw more, with no error); the pyramid's too.
  for (const double curvature : {1.5, -2.0, 1e36, 1e300}) {
    o = {};
    o.curvature = curvature;
    EXPECT_THROW(computeViewshed(c, f, {1, 1, 2.0}, o), InvalidArgument) << curvature;
    ViewshedPyramidOptions p;
    p.curvature = curvature;
    try {
      buildViewshedPyramid(c, f, p);
      ADD_FAILURE() << "a pyramid for a curvature of " << curvature;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("within -1 .. 1 per ground unit"), std::string::npos) << e.what();
    }
  }
  o = {};
  o.curvature = 1.0;
  EXPECT_NO_THROW(computeViewshed(c, f, {1, 1, 2.0}, o));
  ViewshedPyramidOptions most;
  most.curvature = -1.0;
  EXPECT_NO_THROW(buildViewshedPyramid(c, f, most));
  EXPECT_THROW(computeCumulativeViewshed(c, f, {}, {}), InvalidArgument);
  HeightField geographic = f;
  geographic.row_cell_size_x.assign(10, 1.0);
  geographic.row_cell_size_y.assign(10, 1.0);
  EXPECT_THROW(computeViewshed(c, geographic, {1, 1, 2.0}, {}), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
