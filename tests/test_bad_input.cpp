// test_bad_input.cpp: the library's side of docs/BAD_INPUT.md: each misuse of the API it
// lists gets the exception it says, with a message that names the problem (the CLI's side is
// the table that scripts/bad_input.sh checks).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "hfvis/hfvis.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::testContext;

// Runs `call`, which must throw E with `words` in its message.
template <typename E>
void expectError(const std::function<void()>& call, const std::string& words) {
  try {
    call();
    ADD_FAILURE() << "no error; expected one naming '" << words << "'";
  } catch (const E& error) {
    EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "another kind of error than expected: " << error.what();
  }
}

HorizonOutputs svfOnly() {
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  return outputs;
}

void horizons(const HeightField& field, const HorizonOptions& options = {},
              HorizonOutputs outputs = svfOnly()) {
  computeHorizons(testContext(), field, options, outputs);
}

// One rule for heights that float32 rounds (the GDAL and EXR readers and the Python package ask
// it): refused above both a thousandth of their range and a hundredth of a cell, kept at either.
TEST(BadInput, HeightsFloat32RoundsTooFar) {
  EXPECT_NO_THROW(requireHeightsKeptInFloat32(0.0, 5.0, 5.0, 1.0));       // flat, exact
  EXPECT_NO_THROW(requireHeightsKeptInFloat32(0.1, 0.0, 100.0, 0.01));    // a thousandth of 100
  EXPECT_NO_THROW(requireHeightsKeptInFloat32(2.4e-4, 4000, 4000, 0.1));  // a flat roof at 4000
  expectError<InvalidArgument>([] { requireHeightsKeptInFloat32(256, 4294900000.0, 4294900100.0, 1.0); },
                               "rounds them by up to 256");
  expectError<InvalidArgument>([] { requireHeightsKeptInFloat32(0.11, 0.0, 100.0, 10.0); }, "subtract");
}

TEST(BadInput, Fields) {
  const HeightField good = makeSyntheticField("noise", 9, 7, 1);
  expectError<InvalidArgument>([] { horizons(HeightField{}); }, "empty");
  HeightField short_of_heights = good;
  short_of_heights.heights.pop_back();
  expectError<InvalidArgument>([&] { horizons(short_of_heights); }, "holds");
  // Cell sizes: finite, within what single precision holds (1e-30 gave a visible area of 0, 1e300
  // a sky-view factor of 1, without a word); the range's ends pass.
  for (double cell : {0.0, -1.0, std::nan(""), 1e-30, 0.99e-6, 1.01e9, 1e300}) {
    HeightField field = good;
    field.cell_size_y = cell;
    expectError<InvalidArgument>([&] { horizons(field); }, "outside 1e-06 .. 1e+09");
    EXPECT_FALSE(cellSizesHeld(field));
  }
  for (double cell : {kLeastCellSize, kMostCellSize}) {
    HeightField field = good;
    field.cell_size_x = field.cell_size_y = cell;
    EXPECT_TRUE(cellSizesHeld(field));
    EXPECT_NO_THROW(validate(field));
  }
  HeightField row_count = good;  // per-row cell sizes: one per row, finite and positive
  row_count.row_cell_size_x.assign(good.height - 1, 1.0);
  row_count.row_cell_size_y.assign(good.height - 1, 1.0);
  expectError<InvalidArgument>([&] { horizons(row_count); }, "one entry per row");
  HeightField row_value = good;
  row_value.row_cell_size_x.assign(good.height, 1.0);
  row_value.row_cell_size_y.assign(good.height, 1.0);
  row_value.row_cell_size_x[2] = std::nan("");
  expectError<InvalidArgument>([&] { horizons(row_value); }, "cell size of row 2");
  row_value.row_cell_size_x[2] = 1e10;
  expectError<InvalidArgument>([&] { horizons(row_value); }, "cell size of row 2 (1e+10 x 1)");
  EXPECT_FALSE(cellSizesHeld(row_value));
  HeightField flat_z = good;
  flat_z.z_scale = 0.0;
  expectError<InvalidArgument>([&] { horizons(flat_z); }, "z-scale");
  HeightField holes = good;
  for (float& h : holes.heights) h = std::numeric_limits<float>::quiet_NaN();
  expectError<InvalidArgument>([&] { horizons(holes); }, "nodata");
  HeightField towering = good;
  towering.heights[3] = 3e38f;
  towering.heights[4] = -3e38f;
  expectError<InvalidArgument>([&] { horizons(towering); }, "float arithmetic");
  // The operations that keep heights from 0 (region visibility, the viewshed, the ray caster)
  // refuse a height beyond the same bound, where a span from the lowest would not show it.
  HeightField high = good;
  high.heights.assign(high.heights.size(), 2e28f);
  RegionSampling a, b;
  a.rectangle = {0, 0, 1, 1};
  b.rectangle = {3, 3, 4, 4};
  expectError<InvalidArgument>(
      [&] { computeRegionPairVisibility(testContext(), high, a, b, RegionVisibilityOptions{}); },
      "float arithmetic");
  expectError<InvalidArgument>([&] { computeViewshed(testContext(), high, Observer{}, ViewshedOptions{}); },
                               "float arithmetic");
  // Nor heights so far from 0 that float32's spacing there passes a tenth of a cell: near 1e9
  // (steps of 64) an eye 20 above the ground was lost, exit 0. Near 1e5 (steps of 1/128) they are
  // kept.
  for (const float offset : {1e9f, 1e5f}) {
    SCOPED_TRACE(offset);
    HeightField far = good;
    for (float& h : far.heights) h = offset + 64.0f * std::round(h);
    Observer eye;
    eye.height = 20.0;
    const auto viewshed = [&] { computeViewshed(testContext(), far, eye, ViewshedOptions{}); };
    const auto pair = [&] {
      computeRegionPairVisibility(testContext(), far, a, b, RegionVisibilityOptions{});
    };
    if (offset > 1e8f) {
      expectError<InvalidArgument>(viewshed, "only in steps of 64");
      expectError<InvalidArgument>(pair, "subtract a constant");
    } else {
      EXPECT_NO_THROW(viewshed());
      EXPECT_NO_THROW(pair());
    }
  }
}

TEST(BadInput, Options) {
  const HeightField field = makeSyntheticField("noise", 9, 7, 1);
  for (int k : {0, -5, kMaxDirections + 1}) {
    HorizonOptions options;
    options.directions = k;
    expectError<InvalidArgument>([&] { horizons(field, options); }, "directions");
  }
  for (double spu : {0.0, -1.0, 65.0, std::nan("")}) {
    HorizonOptions options;
    options.samples_per_unit = spu;
    expectError<InvalidArgument>([&] { horizons(field, options); }, "samples per unit");
  }
  for (double c : {std::nan(""), 2.0, -std::numeric_limits<double>::infinity()}) {
    HorizonOptions options;
    options.curvature = c;
    expectError<InvalidArgument>([&] { horizons(field, options); }, "curvature coefficient");
  }
  for (double d : {-1.0, std::nan("")}) {
    HorizonOptions options;
    options.max_distance = d;
    expectError<InvalidArgument>([&] { horizons(field, options); }, "maximum distance");
  }
  HorizonOptions within;
  within.max_distance = 1e-9;  // blocks of a window this short would overflow an int
  expectError<InvalidArgument>([&] { horizons(field, within); }, "is too short for a field of this size");
  BounceOptions curved_bounce;
  curved_bounce.curvature = earthCurvature();
  ExitRadiance lit;
  lit.width = field.width;
  lit.height = field.height;
  lit.channels = {std::vector<float>(field.pixelCount(), 1.0f)};
  expectError<InvalidArgument>([&] { computeBounce(testContext(), field, lit, curved_bounce); },
                               "curvature is not supported");
  expectError<InvalidArgument>([&] { horizons(field, {}, HorizonOutputs{}); }, "output");
  HorizonOptions budget;
  budget.memory_budget_bytes = 16;
  expectError<MemoryBudgetError>([&] { horizons(makeSyntheticField("noise", 64, 64, 1), budget); }, "budget");
  IntervisibilityOptions naive;
  naive.method = IntervisibilityMethod::Naive;
  IntervisibilityOutputs statistics;
  statistics.statistics = true;
  expectError<InvalidArgument>([&] { computeIntervisibility(testContext(), field, naive, statistics); },
                               "statistics");
  // Enum values cast from bad integers: refused naming the method (an OpenCL error, or a run as
  // one of the methods, before).
  HorizonOptions bad_horizon;
  bad_horizon.method = static_cast<HorizonMethod>(7);
  expectError<InvalidArgument>([&] { horizons(field, bad_horizon); }, "unknown horizon method 7");
  IntervisibilityOptions bad_tree;
  bad_tree.method = static_cast<IntervisibilityMethod>(9);
  IntervisibilityOutputs counts;
  counts.visible_count = true;
  expectError<InvalidArgument>([&] { computeIntervisibility(testContext(), field, bad_tree, counts); },
                               "unknown intervisibility method 9");
  ExitRadiance radiance;
  radiance.width = 3;
  radiance.height = 3;
  radiance.channels = {std::vector<float>(9, 1.0f)};
  expectError<InvalidArgument>([&] { computeBounce(testContext(), field, radiance, BounceOptions{}); },
                               "one value per height");
}

TEST(BadInput, PotentiallyVisibleSets) {
  const HeightField field = makeSyntheticField("noise", 9, 7, 1);
  PvsOptions options;
  options.samples = 10;
  auto pvs = [&](const PvsGrid& grid) { computePvs(testContext(), field, grid, options); };
  PvsGrid grid;
  grid.view_cell = 4;
  grid.tile = 2;
  PvsGrid bad = grid;
  bad.view_cell = 9;
  expectError<InvalidArgument>([&] { pvs(bad); }, "view cell size must be 1 .. 8");
  bad = grid;
  bad.tile = 0;
  expectError<InvalidArgument>([&] { pvs(bad); }, "tile size");
  bad = grid;
  bad.band_low = 2.0;
  bad.band_high = 1.0;
  expectError<InvalidArgument>([&] { pvs(bad); }, "0 <= H0 <= H1");
  bad.band_low = 0.0;
  bad.band_high = 1e39;  // (infinite in float: the rays' origins were blamed)
  expectError<InvalidArgument>([&] { pvs(bad); }, "0 <= H0 <= H1 <= 1e+12 (got 0, 1e+39)");
  PvsOptions bad_method = options;
  bad_method.method = static_cast<PvsMethod>(99);
  expectError<InvalidArgument>([&] { computePvs(testContext(), field, grid, bad_method); },
                               "unknown PVS method 99");
  bad = grid;
  bad.mask.assign(3, 1);
  expectError<InvalidArgument>([&] { pvs(bad); }, "mask has 3 entries");
  bad.mask.assign(4, 0);
  expectError<InvalidArgument>([&] { pvs(bad); }, "selects no view cell");
  options.samples = 0;
  expectError<InvalidArgument>([&] { pvs(grid); }, "needs a budget");
  options.samples = 10;
  options.pixel_error = -1.0;
  expectError<InvalidArgument>([&] { pvs(grid); }, "finite and >= 0");
  const HeightField line = makeSyntheticField("noise", 9, 1, 1);
  expectError<InvalidArgument>([&] { computeDensePvs(testContext(), line, grid); }, "at least 2 x 2");
}

TEST(BadInput, ContextsAndFiles) {
  ContextOptions unknown;
  unknown.device = "a device nobody has";
  expectError<NoDeviceError>([&] { ComputeContext::create(unknown); }, "no OpenCL device matches");
  ContextOptions no_kernels = ContextOptions::fromEnvironment();
  no_kernels.kernel_dir = "/nonexistent/kernels";
  const ComputeContext context = ComputeContext::create(no_kernels);
  expectError<IoError>(
      [&] { computeHorizons(context, makeSyntheticField("noise", 9, 7, 1), HorizonOptions{}, svfOnly()); },
      "cannot read kernel source");
  expectError<IoError>([] { readHeightField("/nonexistent/field.exr"); }, "no such file");
  ImageChannels image;
  image.width = image.height = 2;
  image.names = {"Y"};
  image.planes = {std::vector<float>(4, 0.0f)};
  expectError<IoError>([&] { writeImage(std::string(HFVIS_TEST_TMP_DIR) + "/bad.xyz", image); },
                       "no image writer");
}

// Issue 26, item 9: a radiance single precision cannot sum over the sky (3e38 gave every
// irradiance infinite) is refused, naming the pixel.
TEST(BadInput, EnvironmentRadianceBeyondSinglePrecision) {
  EnvironmentMap map;
  map.width = 8;
  map.height = 4;
  map.channels = 1;
  map.names = {"Y"};
  map.radiance.assign(32, 1.0f);
  map.radiance[9] = 3e38f;
  expectError<InvalidArgument>([&] { validate(map); }, "at most 1e+30");
  expectError<InvalidArgument>([&] { validate(map); }, "column 1, row 1");
}

// Issue 26, item 12: a huge number in a message is printed short, not with its 300 digits.
TEST(BadInput, HugeNumbersInMessagesAreShort) {
  HeightField field = makeSyntheticField("noise", 9, 7, 1);
  field.z_scale = -1e300;
  try {
    validate(field);
    ADD_FAILURE() << "a negative z-scale passed";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("-1e+300"), std::string::npos) << error.what();
    EXPECT_LT(std::string(error.what()).size(), 100u) << error.what();
  }
}

}  // namespace
}  // namespace hfvis
