// test_shading.cpp: the sun's light on a height field: the disc's visible part, a flat plane
// (every point sees the whole sun; direct = sin(elevation)), a wall's shadow with its soft
// edge (the disc partly above the wall's top), the swept azimuth, and bad suns.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "hfvis/errors.hpp"
#include "hfvis/shading.hpp"
#include "hfvis/synthetic_fields.hpp"
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
    const SunShading s = computeSunShading(testContext(), flat, sun);
    for (std::size_t p = 0; p < s.sun.size(); ++p) {
      ASSERT_EQ(s.sun[p], 1.0f) << azimuth;
      ASSERT_NEAR(s.direct[p], 0.5f, 1e-6f) << azimuth;
    }
    sun.position.elevation_deg = 0.0;
    const SunShading low = computeSunShading(testContext(), flat, sun);
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
  const SunShading s = computeSunShading(testContext(), field, sun);
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

TEST(SunShading, RefusesBadSuns) {
  const HeightField flat = makeSyntheticField("flat", 5, 5);
  SunLight sun;
  sun.size_deg = 0.0;
  EXPECT_THROW(computeSunShading(testContext(), flat, sun), InvalidArgument);
  sun.size_deg = 0.53;
  sun.position.elevation_deg = 91.0;
  EXPECT_THROW(computeSunShading(testContext(), flat, sun), InvalidArgument);
  sun.position = {std::nan(""), 10.0};
  EXPECT_THROW(computeSunShading(testContext(), flat, sun), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
