// test_sun_shading.cpp: the sun's light on a height field: the disc's visible part, a flat plane
// (every point sees the whole sun; direct = sin(elevation)), a wall's shadow with its soft
// edge (the disc partly above the wall's top), the swept azimuth, bad suns, and the device
// against the scalar reference on every hard case in both layouts.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "hfvis/errors.hpp"
#include "hfvis/sun_shading.hpp"
#include "hfvis_testing/horizon_reference.hpp"
#include "hfvis_testing/sun_shading_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "core/lattice_geometry.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::fieldFrom;
using testing::testContext;

constexpr double kDegree = M_PI / 180.0;

TEST(SunShading, DiscAboveAStraightHorizon) {
  const double r = 0.25 * kDegree;
  EXPECT_DOUBLE_EQ(discAboveHorizon(0.0, r), 0.5);
  EXPECT_DOUBLE_EQ(discAboveHorizon(r, r), 1.0);
  EXPECT_DOUBLE_EQ(discAboveHorizon(2 * r, r), 1.0);
  EXPECT_DOUBLE_EQ(discAboveHorizon(-r, r), 0.0);
  double last = -1.0;
  for (int i = -10; i <= 10; ++i) {
    const double f = discAboveHorizon(0.1 * i * r, r);
    EXPECT_GT(f, last);
    EXPECT_NEAR(f + discAboveHorizon(-0.1 * i * r, r), 1.0, 1e-12);  // the segments above and below
    last = f;
  }
  // The segment above a chord half a radius below the centre: (2 pi / 3 + sqrt(3) / 4 ...) / pi.
  EXPECT_NEAR(discAboveHorizon(0.5 * r, r), 1.0 - (std::acos(0.5) - 0.5 * std::sqrt(0.75)) / M_PI, 1e-12);
}

// A flat plane sees the whole sun above its own horizon (0; -pi/2 looking out at the border)
// and receives sin(elevation); a sun centred on the horizon is half seen in the interior.
TEST(SunShading, FlatPlane) {
  const HeightField flat = makeSyntheticField("flat", 23, 17);
  for (double azimuth : {0.0, 37.0, 90.0, 200.0, 359.0}) {
    SunLight sun;
    sun.position = {azimuth, 30.0};
    const SunShadingResult s = computeSunShading(testContext(), flat, sun);
    for (std::size_t p = 0; p < s.sun.size(); ++p) {
      ASSERT_EQ(s.sun[p], 1.0f) << azimuth;
      ASSERT_NEAR(s.direct[p], 0.5f, 1e-6f) << azimuth;
    }
    sun.position.elevation_deg = 0.0;
    const SunShadingResult low = computeSunShading(testContext(), flat, sun);
    EXPECT_FLOAT_EQ(low.sun[8 * 23 + 11], 0.5f);
    EXPECT_EQ(low.direct[8 * 23 + 11], 0.0f);
  }
}

// A north-south wall 10 high at column 20, the sun in the west (compass 270) at 20 degrees:
// east of the wall its top stands atan(10 / d) high, d the ground distance (cells 1.25 wide).
// Shadow where that is above the sun's disc, light where below it, the disc's part in between;
// west of the wall, light. The direct irradiance of the lit flat ground is sin(20 degrees).
TEST(SunShading, AWallsShadowAndItsSoftEdge) {
  const int w = 80, h = 9, wall = 20;
  std::vector<float> heights(w * h, 0.0f);
  for (int r = 0; r < h; ++r) heights[r * w + wall] = 10.0f;
  HeightField field = fieldFrom(w, h, heights);
  field.cell_size_x = 1.25;
  SunLight sun;
  sun.position = {270.0, 20.0};
  sun.size_deg = 2.0;  // a wide disc: several pixels of penumbra
  const SunShadingResult s = computeSunShading(testContext(), field, sun);
  EXPECT_NEAR(s.azimuth, M_PI, 1e-9);
  const double radius = 1.0 * kDegree, elevation = 20.0 * kDegree;
  int shadow = 0, penumbra = 0, lit = 0;
  for (int c = wall + 1; c < w; ++c) {
    const double d = 1.25 * (c - wall), top = std::atan(10.0 / d);
    const float seen = s.sun[4 * w + c];
    EXPECT_NEAR(seen, discAboveHorizon(elevation - top, radius), 1e-5) << "column " << c;
    shadow += seen == 0.0f;
    lit += seen == 1.0f;
    penumbra += seen > 0.0f && seen < 1.0f;
    if (seen == 1.0f) {
      EXPECT_NEAR(s.direct[4 * w + c], std::sin(elevation), 1e-6) << "column " << c;
    }
  }
  EXPECT_GT(shadow, 5);
  EXPECT_GT(penumbra, 1);
  EXPECT_GT(lit, 20);
  for (int c = 0; c < wall; ++c) EXPECT_EQ(s.sun[4 * w + c], 1.0f) << "column " << c;
}

// Issue 26, item 13: a point sun (size 0) is a legitimate request: hard shadows, every pixel
// wholly lit or wholly in shadow, as the wall's top stands below or above the sun.
TEST(SunShading, APointSunCastsHardShadows) {
  const int w = 80, h = 9, wall = 20;
  std::vector<float> heights(w * h, 0.0f);
  for (int r = 0; r < h; ++r) heights[r * w + wall] = 10.0f;
  HeightField field = fieldFrom(w, h, heights);
  SunLight sun;
  sun.position = {270.0, 20.0};
  sun.size_deg = 0.0;
  const SunShadingResult s = computeSunShading(testContext(), field, sun);
  for (int c = wall + 1; c < w; ++c) {
    const double top = std::atan(10.0 / (c - wall));
    if (std::fabs(top - 20.0 * kDegree) < 1e-3) continue;  // the shadow's edge itself
    EXPECT_EQ(s.sun[4 * w + c], top > 20.0 * kDegree ? 0.0f : 1.0f) << "column " << c;
  }
  EXPECT_DOUBLE_EQ(discAboveHorizon(1e-9, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(discAboveHorizon(-1e-9, 0.0), 0.0);
}

// Issue 26, item 10: a sun below the astronomical horizon lights nothing, as in computeInsolation
// (terrain beyond the field is level): not flat ground, not a border pixel whose rays leave the
// field, not a peak whose own horizon lies lower.
TEST(SunShading, ASunBelowElevationZeroLightsNothing) {
  std::vector<float> heights(15 * 15, 0.0f);
  for (int r = 0; r < 15; ++r)
    for (int c = 0; c < 15; ++c) heights[r * 15 + c] = 20.0f - 2.0f * std::hypot(c - 7.0, r - 7.0);  // a cone
  for (const HeightField& field : {makeSyntheticField("flat", 12, 10), fieldFrom(15, 15, heights)}) {
    for (const double elevation : {-30.0, -1.0}) {
      SunLight sun;
      sun.position = {180.0, elevation};
      const SunShadingResult s = computeSunShading(testContext(), field, sun);
      for (std::size_t p = 0; p < s.sun.size(); ++p) {
        EXPECT_EQ(s.sun[p], 0.0f) << "pixel " << p << ", sun at " << elevation << " degrees";
        EXPECT_EQ(s.direct[p], 0.0f) << "pixel " << p;
      }
    }
  }
}

TEST(SunShading, RefusesBadSuns) {
  const HeightField flat = makeSyntheticField("flat", 5, 5);
  SunLight sun;
  sun.size_deg = -0.1;
  EXPECT_THROW(computeSunShading(testContext(), flat, sun), InvalidArgument);
  sun.size_deg = 10.5;
  EXPECT_THROW(computeSunShading(testContext(), flat, sun), InvalidArgument);
  sun.size_deg = 0.53;
  sun.position.elevation_deg = 91.0;
  EXPECT_THROW(computeSunShading(testContext(), flat, sun), InvalidArgument);
  sun.position = {std::nan(""), 10.0};
  EXPECT_THROW(computeSunShading(testContext(), flat, sun), InvalidArgument);
}

// The sun's sweep takes the cheapest integer step within 0.02 degree of its azimuth: of up to 64
// pixels where one is, else a longer one (next to the axes, where the nearest short steps are up
// to half of atan(1/64) = 0.448 degree away). Over azimuths 0.1 degree apart: how far, and how
// long the steps get (shading.hpp and docs/COMMAND_LINE.md quote these figures).
TEST(SunShading, SweptStepIsCloseToTheSun) {
  const HeightField field = makeSyntheticField("flat", 8, 8);
  double worst = 0.0;
  int long_steps = 0, longest = 0;
  auto step = [&](double azimuth_deg) {
    SweepOptions options;
    options.directions = 1;
    options.azimuth_offset = azimuth_deg * kDegree;
    const detail::LatticeDirection d = detail::latticeDirections(field, options, true, 0.02 * kDegree)[0];
    worst = std::max(worst, std::fabs(d.azimuth - options.azimuth_offset) / kDegree);
    const int length = std::max(std::abs(d.a), std::abs(d.b));
    longest = std::max(longest, length);
    return length;
  };
  const int n = 3600;
  for (int i = 0; i < n; ++i) long_steps += step(i * 0.1 - 180.0 + 0.05) > detail::kMaxLatticeStep;
  // The longest steps lie just beyond 0.02 degree from an axis: there, every 0.0005 degree.
  for (int i = 40; i <= 200; ++i) step(i * 0.0005);
  std::printf("swept step: at most %.4f degree off; %.1f %% of azimuths take a step over 64 pixels, the longest %d\n",
              worst, 100.0 * long_steps / n, longest);
  EXPECT_LE(worst, 0.02);
  EXPECT_LT(long_steps, n / 4);
}

// The device against the scalar reference (the horizon reference, then the same per-pixel
// step): equal where the device divides correctly rounded; elsewhere the horizons' few-ulp
// differences, times the disc's steepest rate of change (about 140 per radian for the 0.53
// degree sun).
TEST(SunShading, MatchesTheScalarReferenceOnEveryHardCase) {
  SunLight sun;
  sun.position = {123.4, 15.0};
  const float tolerance = 200.0f * testing::divisionTolerance();
  testing::forEachLayout([&](const ComputeContext& context) {
    testing::forEachHardCase([&](const std::string&, const HeightField& field) {
      const SunShadingResult got = computeSunShading(context, field, sun);
      const SunShadingResult expected = referenceSunShading(field, sun);
      EXPECT_EQ(got.azimuth, expected.azimuth);
      EXPECT_TRUE(testing::nearlyEqual(got.sun, expected.sun, tolerance));
      EXPECT_TRUE(testing::nearlyEqual(got.direct, expected.direct, tolerance));
    });
  });
}

// A long step (the sun 0.3 degree from an axis: a step of over 64 pixels) runs through the same kernel: its
// horizons equal the scalar reference's, on the hard cases, in both layouts.
TEST(SunShading, LongStepsMatchTheReference) {
  for (const char* name : {"spikes", "cliff", "nan_holes", "noise"}) {
    const HeightField field = makeSyntheticField(name, 300, 40);
    HorizonOptions options;
    options.directions = 1;
    options.azimuth_offset = 0.3 * kDegree;
    options.azimuth_tolerance = 0.02 * kDegree;
    HorizonOutputs outputs;
    outputs.horizon_angles = true;
    const detail::LatticeDirection d = detail::latticeDirections(field, options, true, options.azimuth_tolerance)[0];
    EXPECT_GT(d.a, detail::kMaxLatticeStep) << name;
    const HorizonResult expected = referenceHorizons(field, options, outputs);
    testing::forEachLayout([&](const ComputeContext& context) {
      const HorizonResult got = computeHorizons(context, field, options, outputs);
      ASSERT_EQ(got.angles.size(), expected.angles.size());
      for (std::size_t p = 0; p < got.angles.size(); ++p) {
        if (std::isnan(expected.angles[p])) {
          ASSERT_TRUE(std::isnan(got.angles[p])) << name << " pixel " << p;
        } else {
          ASSERT_EQ(got.angles[p], expected.angles[p]) << name << " pixel " << p;
        }
      }
    });
  }
}

}  // namespace

}  // namespace hfvis
