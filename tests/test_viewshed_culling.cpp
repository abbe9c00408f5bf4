// test_viewshed_culling.cpp: Stewart's culling pyramid (buildViewshedPyramid): every point it
// culls is hidden by brute force (hfvis_testing/viewshed_reference.hpp), clear of grazing; a viewshed
// with it equals one without, bit for bit; on rough terrain, a wall whose shadow lies across
// azimuth 0 (sector ranges that wrap), notched ridges, the hard cases, curvature, target
// heights and both layouts; bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "hfvis/viewshed.hpp"
#include "hfvis_testing/viewshed_reference.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::forEachLayout;
using testing::testContext;

HeightField fractalCrop(int x0, int y0, int w, int h) {
  static const HeightField fractal = readHeightField(std::string(HFVIS_DATA_DIR) + "/fractal_256.exr");
  return testing::cropField(fractal, x0, y0, w, h);
}

struct Culling {
  std::size_t targets = 0, culled = 0, hidden = 0;
};

// The viewshed with the pyramid against the one without (bit for bit, the culled count with
// them) and every culled point against brute force: hidden, the surface rising strictly above
// its sight line between eye and target.
Culling checkCulling(const ComputeContext& context, const HeightField& f, const Observer& o,
                     const ViewshedOptions& plain, const ViewshedPyramid& pyramid) {
  ViewshedOptions culled = plain;
  culled.pyramid = &pyramid;
  ViewshedOutputs outputs;
  outputs.angle = true;
  outputs.culled_mask = true;
  // The culled one first: the rays' bounds buffer the context keeps then holds another
  // observer's, which the culled viewshed must not read (its rays stop short where it culls).
  const ViewshedResult got = computeViewshed(context, f, o, culled, outputs);
  outputs.culled_mask = false;
  const ViewshedResult exact = computeViewshed(context, f, o, plain, outputs);
  // The kernel's query against the scalar one: it culls nothing the scalar one keeps (its float
  // rounding is widened the conservative way) and keeps few that it culls.
  const std::vector<float> want = referenceCulledMask(f, pyramid, o, plain);
  std::size_t extra = 0, kept = 0, wanted = 0;
  for (std::size_t p = 0; p < f.pixelCount(); ++p) {
    wanted += want[p] == 1.0f;
    extra += got.culled_mask[p] == 1.0f && want[p] != 1.0f;
    kept += want[p] == 1.0f && got.culled_mask[p] != 1.0f;
  }
  EXPECT_EQ(extra, 0u) << "points culled that the scalar query keeps";
  const std::size_t node_points = std::size_t(1) << (2 * pyramid.finest_level);
  EXPECT_LE(kept, wanted / 10 + node_points) << "points the scalar query culls, of " << wanted;
  Culling c;
  std::size_t mismatches = 0;
  for (std::size_t p = 0; p < f.pixelCount(); ++p) {
    const bool same = exact.visible[p] == got.visible[p] || (std::isnan(exact.visible[p]) && std::isnan(got.visible[p]));
    if (!same && ++mismatches <= 5)
      ADD_FAILURE() << "point " << p % f.width << "," << p / f.width << ": culled " << got.visible[p] << ", exact "
                    << exact.visible[p];
    EXPECT_TRUE(got.angle[p] == exact.angle[p] || (std::isnan(got.angle[p]) && std::isnan(exact.angle[p])));
    if (std::isnan(got.culled_mask[p])) {
      EXPECT_FALSE(std::isfinite(f.heights[p]));
      continue;
    }
    ++c.targets;
    c.hidden += exact.visible[p] == 0.0f;
    if (got.culled_mask[p] != 1.0f) continue;
    ++c.culled;
    const int col = static_cast<int>(p % f.width), row = static_cast<int>(p / f.width);
    const SightLine s = referenceSightLine(f, o, plain, col, row);
    if (s.visible || !(s.interior_rise > 0.0))
      ADD_FAILURE() << "culled " << col << "," << row << " but brute force finds it "
                    << (s.visible ? "visible" : "hidden") << ", the surface " << s.interior_rise
                    << " above the sight line at most";
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(got.culled, c.culled);
  return c;
}

ViewshedPyramid pyramidFor(const ComputeContext& context, const HeightField& f, double target_height = 0.0,
                           double curvature = 0.0, int finest_level = ViewshedPyramidOptions{}.finest_level) {
  ViewshedPyramidOptions options;
  options.target_height = target_height;
  options.curvature = curvature;
  options.finest_level = finest_level;
  return buildViewshedPyramid(context, f, options);
}

ViewshedPyramidOptions sectorsOf(int sectors, int directions_per_sector, int finest_level) {
  ViewshedPyramidOptions options;
  options.sectors = sectors;
  options.directions_per_sector = directions_per_sector;
  options.finest_level = finest_level;
  return options;
}

TEST(ViewshedCulling, RoughTerrainCullsOnlyHiddenPoints) {
  const HeightField f = fractalCrop(40, 60, 97, 83);
  forEachLayout([&](const ComputeContext& context) {
    const ViewshedPyramid pyramid = pyramidFor(context, f, 0.0, 0.0, 1);
    EXPECT_EQ(pyramid.levels.front().k, 1);
    EXPECT_EQ(pyramid.levels.back().nodes_x, 1);
    EXPECT_EQ(pyramid.levels.back().nodes_y, 1);
    std::size_t culled = 0, hidden = 0;
    for (const Observer& o : std::vector<Observer>{{48, 41, 2.0}, {10, 70, 0.0}, {48, 41, 60.0}, {0, 0, 2.0},
                                                   {96, 40, 5.0}, {50, 82, 1.0}, {20, 20, 0.5}}) {
      SCOPED_TRACE(std::to_string(o.col) + "," + std::to_string(o.row) + " at " + std::to_string(o.height));
      const Culling c = checkCulling(context, f, o, {}, pyramid);
      culled += c.culled;
      hidden += c.hidden;
    }
    // The pyramid culls a share of what is hidden (not a stub that culls nothing).
    EXPECT_GT(culled, hidden / 4) << culled << " culled of " << hidden << " hidden";
    std::printf("rough terrain: %zu culled of %zu hidden\n", culled, hidden);
    // Wide sectors, wide nodes: a node's azimuth range often begins in one sector and runs into
    // the next, which must be checked too.
    const ViewshedPyramid coarse = buildViewshedPyramid(context, f, sectorsOf(4, 16, 1));
    std::size_t wide_culled = 0;
    for (const Observer& o : std::vector<Observer>{{48, 41, 2.0}, {10, 70, 0.0}, {20, 20, 0.5}, {90, 10, 1.0}})
      wide_culled += checkCulling(context, f, o, {}, coarse).culled;
    EXPECT_GT(wide_culled, 0u);
  });
}

TEST(ViewshedCulling, CoarseNodesAndEyesNearTheBorder) {
  // Nodes of 4 .. 16 points a side; eyes near the box's edges and inside a node's column or row
  // range, where a node's rays run the long way round the border from some of its corners.
  const HeightField f = fractalCrop(150, 150, 64, 58);
  std::size_t culled = 0;
  for (int level : {2, 3, 4}) {
    SCOPED_TRACE(level);
    const ViewshedPyramid pyramid = pyramidFor(testContext(), f, 0.0, 0.0, level);
    for (const Observer& o : std::vector<Observer>{{9, 3, 1.0}, {33, 3, 0.5}, {3, 40, 2.0}, {60, 55, 0.0}, {63, 20, 1.0}}) {
      SCOPED_TRACE(std::to_string(o.col) + "," + std::to_string(o.row));
      culled += checkCulling(testContext(), f, o, {}, pyramid).culled;
      ViewshedOptions near;  // a box within the field
      near.max_distance = 25.0;
      culled += checkCulling(testContext(), f, o, near, pyramid).culled;
    }
  }
  EXPECT_GT(culled, 0u);
}

TEST(ViewshedCulling, RealTerrainCullsAShareOfTheHiddenPoints) {
  // The bundled DEM cropped to 200 x 160, nodes of 4 x 4 points (the default).
  const HeightField dem =
      testing::cropField(readHeightField(std::string(HFVIS_DATA_DIR) + "/jacksboro_fault_dem.exr"), 100, 80, 200, 160);
  const ViewshedPyramid pyramid = pyramidFor(testContext(), dem);
  std::size_t culled = 0, hidden = 0;
  for (const Observer& o : std::vector<Observer>{{100, 80, 2.0}, {10, 10, 0.0}, {150, 120, 30.0}}) {
    SCOPED_TRACE(std::to_string(o.col) + "," + std::to_string(o.row));
    const Culling c = checkCulling(testContext(), dem, o, {}, pyramid);
    culled += c.culled;
    hidden += c.hidden;
  }
  EXPECT_GT(culled, hidden / 5) << culled << " culled of " << hidden << " hidden";
  std::printf("DEM: %zu culled of %zu hidden\n", culled, hidden);
}

// Flat ground at 0 with a wall of height 50 along column `wall` (every row but the notch's).
HeightField wallField(int width, int height, int wall, int notch_row = -1, int notch_rows = 0) {
  HeightField f;
  f.width = width;
  f.height = height;
  f.heights.assign(static_cast<std::size_t>(width) * height, 0.0f);
  for (int y = 0; y < height; ++y)
    if (y < notch_row || y >= notch_row + notch_rows) f.heights[static_cast<std::size_t>(y) * width + wall] = 50.0f;
  return f;
}

TEST(ViewshedCulling, SectorRangesWrappingAzimuthZero) {
  // The eye east of the wall: the targets west of it see it at azimuth about 0, where the first
  // sector begins, so the nodes on the eye's rows meet the last sector and the first.
  const HeightField f = wallField(80, 61, 30);
  forEachLayout([&](const ComputeContext& context) {
    const ViewshedPyramid pyramid = pyramidFor(context, f);
    for (const Observer& o : std::vector<Observer>{{60, 30, 2.0}, {5, 30, 2.0}}) {
      SCOPED_TRACE(std::to_string(o.col));
      const Culling c = checkCulling(context, f, o, {}, pyramid);
      ViewshedOptions options;
      options.pyramid = &pyramid;
      ViewshedOutputs outputs;
      outputs.culled_mask = true;
      const ViewshedResult r = computeViewshed(context, f, o, options, outputs);
      // Behind the wall on the eye's own rows (their nodes' azimuth ranges wrap for the eye in
      // the east) the targets are culled.
      std::size_t behind = 0, culled = 0;
      for (int y = 26; y < 34; ++y)
        for (int x = 0; x < f.width; ++x)
          if (o.col > 30 ? x < 26 : x > 34) {
            ++behind;
            culled += r.culled_mask[static_cast<std::size_t>(y) * f.width + x] == 1.0f;
          }
      EXPECT_GT(culled, behind / 2) << culled << " of " << behind;
      EXPECT_GT(c.culled, c.hidden / 2);
    }
  });
}

TEST(ViewshedCulling, NotchedRidgesAreNotCulledThrough) {
  // A wall with narrow notches (1 and 2 grid points): targets far behind them see the eye
  // through a gap narrower than the spacing of the horizons' directions there.
  HeightField f = wallField(150, 90, 100, 40, 1);
  for (int y : {60, 61}) f.heights[static_cast<std::size_t>(y) * f.width + 100] = 0.0f;
  forEachLayout([&](const ComputeContext& context) {
    const ViewshedPyramid pyramid = buildViewshedPyramid(context, f, sectorsOf(8, 4, 1));
    std::size_t culled = 0;
    for (const Observer& o : std::vector<Observer>{{103, 40, 1.0}, {104, 61, 1.0}, {110, 50, 3.0}}) {
      SCOPED_TRACE(std::to_string(o.col) + "," + std::to_string(o.row));
      const Culling c = checkCulling(context, f, o, {}, pyramid);
      culled += c.culled;
      EXPECT_LT(c.hidden, c.targets);  // targets behind the notch are seen
    }
    EXPECT_GT(culled, 0u);
  });
}

TEST(ViewshedCulling, HardCases) {
  forEachLayout([&](const ComputeContext& context) {
    std::size_t culled = 0;
    for (const std::string& name : syntheticFieldNames()) {
      SCOPED_TRACE(name);
      const HeightField f = makeSyntheticField(name, 61, 53);
      const ViewshedPyramid pyramid = pyramidFor(context, f, 0.0, 0.0, 1);
      for (Observer o : std::vector<Observer>{{30, 26, 1.5}, {3, 50, 0.0}}) {
        if (!std::isfinite(f.at(o.col, o.row))) continue;
        culled += checkCulling(context, f, o, {}, pyramid).culled;
      }
    }
    EXPECT_GT(culled, 0u);
  });
}

TEST(ViewshedCulling, TargetHeightCurvatureAndOptions) {
  HeightField f = fractalCrop(100, 20, 90, 70);
  f.cell_size_x = 2.0;
  f.cell_size_y = 1.5;
  f.heights[33 * 90 + 12] = NAN;
  forEachLayout([&](const ComputeContext& context) {
    ViewshedOptions options;
    options.target_height = 1.5;
    options.curvature = 0.002;
    const ViewshedPyramid pyramid = pyramidFor(context, f, 1.5, 0.002, 1);
    for (const Observer& o : std::vector<Observer>{{45, 35, 2.0}, {5, 60, 20.0}}) checkCulling(context, f, o, options, pyramid);
    options.max_distance = 60.0;
    options.azimuth_from_deg = 300.0;
    options.azimuth_to_deg = 100.0;
    options.elevation_max_deg = 10.0;
    checkCulling(context, f, {45, 35, 2.0}, options, pyramid);
    // Negative curvature (refraction beyond 1) raises far terrain.
    ViewshedOptions raised;
    raised.curvature = -0.003;
    checkCulling(context, f, {45, 35, 2.0}, raised, pyramidFor(context, f, 0.0, -0.003, 1));
  });
}

TEST(ViewshedCulling, CumulativeEqualsWithout) {
  const HeightField f = fractalCrop(10, 10, 70, 64);
  const ViewshedPyramid pyramid = pyramidFor(testContext(), f);
  const std::vector<Observer> observers = {{3, 3, 2.0}, {35, 30, 2.0}, {69, 63, 10.0}};
  ViewshedOptions culled;
  culled.pyramid = &pyramid;
  EXPECT_EQ(computeCumulativeViewshed(testContext(), f, observers, culled).count,
            computeCumulativeViewshed(testContext(), f, observers, {}).count);
}

TEST(ViewshedCulling, BadInputIsRefused) {
  const HeightField f = fractalCrop(0, 0, 40, 30);
  const ViewshedPyramid pyramid = pyramidFor(testContext(), f, 1.0);
  const Observer o{20, 15, 2.0};
  ViewshedOptions options;
  options.pyramid = &pyramid;
  EXPECT_THROW(computeViewshed(testContext(), f, o, options), InvalidArgument);  // built for target height 1
  options.target_height = 1.0;
  EXPECT_NO_THROW(computeViewshed(testContext(), f, o, options));
  options.curvature = 0.001;
  EXPECT_THROW(computeViewshed(testContext(), f, o, options), InvalidArgument);
  options.curvature = 0.0;
  HeightField other = f;
  other.heights[7] += 1.0f;
  EXPECT_THROW(computeViewshed(testContext(), other, o, options), InvalidArgument);
  other = f;
  other.z_scale = 2.0;
  EXPECT_THROW(computeViewshed(testContext(), other, o, options), InvalidArgument);
  EXPECT_THROW(computeCumulativeViewshed(testContext(), other, {o}, options), InvalidArgument);
  // A pyramid altered out of the shape buildViewshedPyramid gives it.
  for (auto alter : std::vector<std::function<void(ViewshedPyramid&)>>{
           [](ViewshedPyramid& p) { p.levels.front().regions.pop_back(); },
           [](ViewshedPyramid& p) { p.sector_start.pop_back(); }, [](ViewshedPyramid& p) { p.levels.pop_back(); },
           [](ViewshedPyramid& p) { p.levels.front().nodes_x += 1; }, [](ViewshedPyramid& p) { p.valid_points.clear(); },
           [](ViewshedPyramid& p) { p.sectors = 0; }, [](ViewshedPyramid& p) { p.levels.clear(); },
           [](ViewshedPyramid& p) { p.sector_width[3] *= 0.5f; }, [](ViewshedPyramid& p) { p.sector_start[2] += 0.1f; }}) {
    ViewshedPyramid bad = pyramid;
    alter(bad);
    ViewshedOptions with = options;
    with.pyramid = &bad;
    EXPECT_THROW(computeViewshed(testContext(), f, o, with), InvalidArgument);
  }
  ViewshedOutputs mask;
  mask.culled_mask = true;
  EXPECT_THROW(computeViewshed(testContext(), f, o, {}, mask), InvalidArgument);  // no pyramid
  for (auto bad : std::vector<std::function<void(ViewshedPyramidOptions&)>>{
           [](ViewshedPyramidOptions& p) { p.sectors = 3; }, [](ViewshedPyramidOptions& p) { p.sectors = 257; },
           [](ViewshedPyramidOptions& p) { p.directions_per_sector = 1; },
           [](ViewshedPyramidOptions& p) { p.finest_level = 0; }, [](ViewshedPyramidOptions& p) { p.finest_level = 13; },
           [](ViewshedPyramidOptions& p) { p.target_height = -1.0; },
           [](ViewshedPyramidOptions& p) { p.target_height = NAN; }, [](ViewshedPyramidOptions& p) { p.curvature = INFINITY; }}) {
    ViewshedPyramidOptions p;
    bad(p);
    EXPECT_THROW(buildViewshedPyramid(testContext(), f, p), InvalidArgument);
  }
  // Many directions: the sweep's steps near the axes lie farther apart than its tolerance; the
  // gaps are measured, not assumed.
  EXPECT_NO_THROW(buildViewshedPyramid(testContext(), fractalCrop(0, 0, 20, 16), sectorsOf(128, 8, 2)));
  // A build that would hold more than its budget on the host is refused before it starts.
  ViewshedPyramidOptions small;
  small.memory_budget_bytes = 64 * 1024;
  EXPECT_THROW(buildViewshedPyramid(testContext(), f, small), MemoryBudgetError);
  HeightField lat = f;
  lat.row_cell_size_x.assign(f.height, 1.0);
  lat.row_cell_size_y.assign(f.height, 1.0);
  EXPECT_THROW(buildViewshedPyramid(testContext(), lat, {}), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
