// test_sky_view_factor.cpp: the sky-view factor (hfvis/sky_view_factor.hpp): the kernels against
// the scalar reference on every hard case in both buffer layouts, the same values as the horizon
// operation's output, and closed forms (a street canyon, a tilted plane, nodata).
#include <gtest/gtest.h>

#include <cmath>

#include "hfvis/horizon.hpp"
#include "hfvis/sky_view_factor.hpp"
#include "hfvis_testing/sky_view_factor_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::nearlyEqual;
using testing::testContext;

HorizonOptions optionsFor(HorizonMethod method, int directions, double samples_per_unit = 1.0) {
  HorizonOptions options;
  options.method = method;
  options.directions = directions;
  options.samples_per_unit = samples_per_unit;
  return options;
}

TEST(SkyViewFactor, KernelsMatchTheScalarReferenceOnEveryHardCase) {
  testing::forEachLayout([](const ComputeContext& context) {
    for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
      for (double spu : {1.0, 2.5}) {
        HorizonOptions options = optionsFor(method, 7, spu);
        options.azimuth_offset = 0.1;
        testing::forEachHardCase([&](const std::string&, const HeightField& field) {
          const auto device = computeSkyViewFactor(context, field, options);
          const auto reference = referenceSkyViewFactor(field, options);
          ASSERT_EQ(device.width, field.width);
          ASSERT_EQ(device.height, field.height);
          EXPECT_EQ(device.directions, 7);
          EXPECT_TRUE(nearlyEqual(device.values, reference.values, testing::divisionTolerance()));
        });
      }
    }
  });
}

// The operation is the horizon sweep with this output alone: the same values, bit for bit.
TEST(SkyViewFactor, EqualsTheHorizonOperationsOutput) {
  const HeightField field = makeSyntheticField("city", 40, 41);
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  const HorizonOptions options = optionsFor(HorizonMethod::Sweep, 16);
  EXPECT_TRUE(nearlyEqual(computeSkyViewFactor(testContext(), field, options).values,
                          computeHorizons(testContext(), field, options, outputs).sky_view_factor, 0.0f));
}

// On the centre of a street canyon 3 pixels to each wall and 4 deep, the walls' top edges stand
// at elevation atan(4 / 3) across the street (sin = 4 / 5) and atan(4 / (3 sqrt 2)) along the
// diagonals (sin = 4 / sqrt 34); along the street the horizon is level. With K = 4 (axes) both
// methods sample the edges exactly: SVF = 1 - (2 / 4) (4 / 5) = 0.6. With K = 8 the sweep's
// diagonal steps (1, 1) meet the edge at a grid vertex: SVF = 1 - (2 (4 / 5) + 4 (4 / sqrt 34)) / 8.
TEST(SkyViewFactor, StreetCanyonHasTheClosedFormValue) {
  const HeightField field = testing::streetCanyon(41, 61, 3, 4.0f);
  const double diagonal = 4.0 / std::sqrt(34.0);
  struct Case {
    HorizonMethod method;
    int directions;
    double expected;
  };
  for (const Case& c : {Case{HorizonMethod::Sweep, 4, 0.6}, Case{HorizonMethod::Naive, 4, 0.6},
                        Case{HorizonMethod::Sweep, 8, 1.0 - (2 * 0.8 + 4 * diagonal) / 8}}) {
    SCOPED_TRACE("K = " + std::to_string(c.directions) + (c.method == HorizonMethod::Naive ? " naive" : " sweep"));
    const auto r = computeSkyViewFactor(testContext(), field, optionsFor(c.method, c.directions));
    for (int row = 20; row <= 40; ++row) EXPECT_NEAR(r.values[row * field.width + 20], c.expected, 1e-5) << row;
  }
}

// A tilted plane h = a x sees no terrain above its tangent plane, yet its sky-view factor is
// below 1: uphill, the plane itself hides sky. SVF = 1 - mean over directions of
// sin(max(0, atan(a cos phi))), for the naive march's exact azimuths.
TEST(SkyViewFactor, TiltedPlaneHidesSkyUphill) {
  const double a = 0.5;
  HeightField field = makeSyntheticField("flat", 33, 33);
  for (int row = 0; row < 33; ++row)
    for (int c = 0; c < 33; ++c) field.heights[row * 33 + c] = float(a * c);
  const int K = 16;
  double expected = 0.0;
  for (int k = 0; k < K; ++k) expected += std::sin(std::max(0.0, std::atan(a * std::cos(2 * M_PI * k / K))));
  expected = 1.0 - expected / K;
  const auto r = computeSkyViewFactor(testContext(), field, optionsFor(HorizonMethod::Naive, K));
  for (int row = 4; row < 29; ++row)
    for (int c = 4; c < 20; ++c) EXPECT_NEAR(r.values[row * 33 + c], expected, 1e-5) << c << "," << row;
}

// Nodata pixels get NaN; every other pixel a value in [0, 1].
TEST(SkyViewFactor, NodataIsNaNAndEveryOtherValueAFraction) {
  const HeightField field = makeSyntheticField("nan_holes", 33, 20);
  const auto r = computeSkyViewFactor(testContext(), field, optionsFor(HorizonMethod::Sweep, 16));
  for (std::size_t p = 0; p < r.values.size(); ++p) {
    if (std::isnan(field.heights[p])) {
      EXPECT_TRUE(std::isnan(r.values[p])) << p;
    } else {
      EXPECT_GE(r.values[p], 0.0f) << p;
      EXPECT_LE(r.values[p], 1.0f) << p;
    }
  }
}

}  // namespace
}  // namespace hfvis
