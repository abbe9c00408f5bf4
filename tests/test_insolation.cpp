// test_insolation.cpp: sunshine hours and direct irradiation over a span of time: the kernel
// against the scalar reference on every hard case in both layouts, the buckets' shared sweeps
// against one exact sweep per step (computeSunShading), and bad options.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "hfvis/errors.hpp"
#include "hfvis/insolation.hpp"
#include "hfvis/sun_shading.hpp"
#include "hfvis_testing/insolation_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::fieldFrom;
using testing::testContext;

constexpr double kDegree = M_PI / 180.0;
// The device against the scalar reference: the same steps and buckets, the horizon kernels
// against their reference (exact but for division rounding) and insolation_add against its
// float mirror (acos within the few ulp OpenCL allows): within 1e-4 relative, NaN at nodata.
// A day in spring at 47 N, steps of 30 minutes; the sun's disc in one layout, a point sun in
// the other.
TEST(Insolation, KernelMatchesTheScalarReferenceOnEveryHardCase) {
  InsolationOptions options;
  options.latitude_deg = 47.0;
  options.longitude_deg = 8.0;
  options.from_utc = parseUtcTime("2026-04-10T00:00:00Z");
  options.to_utc = parseUtcTime("2026-04-11T00:00:00Z");
  options.step_minutes = 30.0;
  options.azimuth_bucket_deg = 2.0;
  testing::forEachLayout([&](const ComputeContext& context) {
    options.size_deg = options.size_deg == 0.53 ? 0.0 : 0.53;
    testing::forEachHardCase([&](const std::string&, const HeightField& field) {
      const InsolationResult device = computeInsolation(context, field, options);
      const InsolationResult reference = referenceInsolation(field, options);
      EXPECT_EQ(device.steps, reference.steps);
      EXPECT_EQ(device.sweeps, reference.sweeps);
      ASSERT_EQ(device.sun_hours.size(), field.pixelCount());
      for (std::size_t p = 0; p < field.pixelCount(); ++p) {
        ASSERT_EQ(std::isnan(device.sun_hours[p]), std::isnan(reference.sun_hours[p])) << p;
        ASSERT_EQ(std::isnan(device.direct[p]), std::isnan(reference.direct[p])) << p;
        if (std::isnan(reference.sun_hours[p])) continue;
        EXPECT_NEAR(device.sun_hours[p], reference.sun_hours[p], 1e-4f * (1.0f + reference.sun_hours[p])) << p;
        EXPECT_NEAR(device.direct[p], reference.direct[p], 1e-4f * (1.0f + reference.direct[p])) << p;
      }
    });
  });
}

// Insolation: the buckets' shared sweeps against one exact sweep per step (computeSunShading),
// over three summer days at 47 N on a wall and cone field (the days' steps share buckets). A bucket sweeps its centre azimuth, up to
// half a bucket from a step's, so pixels at a shadow's edge may gain or lose a step: the hours
// agree within a step a day at nearly every pixel and within 0.05 h on the mean, and the
// irradiation within 1 % on the mean. Nodata stays NaN.
TEST(Insolation, BucketsAgreeWithASweepPerStep) {
  const int w = 64, h = 48;
  std::vector<float> heights(w * h, 0.0f);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      heights[r * w + c] = std::max(0.0f, 12.0f - 0.8f * std::hypot(c - 40.0f, r - 20.0f));
      if (c == 15 && r > 5 && r < 40) heights[r * w + c] = 8.0f;  // a wall
    }
  heights[3 * w + 3] = std::nanf("");
  const HeightField field = fieldFrom(w, h, heights);
  InsolationOptions options;
  options.latitude_deg = 47.0;
  options.longitude_deg = 8.0;
  options.from_utc = parseUtcTime("2026-06-21T00:00:00Z");
  options.to_utc = parseUtcTime("2026-06-24T00:00:00Z");
  options.step_minutes = 20.0;
  options.azimuth_bucket_deg = 1.0;  // wide buckets: the test of sharing
  const InsolationResult got = computeInsolation(testContext(), field, options);
  std::vector<double> hours(w * h, 0.0), direct(w * h, 0.0);
  int steps = 0;
  for (double t = options.from_utc; t < options.to_utc; t += 1200.0) {
    SunLight sun;
    sun.position = sunPosition(t + 600.0, options.latitude_deg, options.longitude_deg);
    if (sun.position.elevation_deg <= -0.265) continue;
    ++steps;
    const SunShadingResult s = computeSunShading(testContext(), field, sun);
    const double elevation = sun.position.elevation_deg * kDegree;
    for (std::size_t p = 0; p < field.pixelCount(); ++p) {
      // computeSunShading's sun is seen against the horizon alone; insolation's also against
      // elevation 0: its direct is discAboveHorizon(e - max(h, 0)) max(0, n . s).
      const float n_dot = s.sun[p] > 0.0f ? s.direct[p] / s.sun[p] : 0.0f;
      const double seen = std::min<double>(s.sun[p], discAboveHorizon(elevation, 0.265 * kDegree));
      hours[p] += (s.sun[p] > 0.5f && elevation > 0.0) ? 1.0 / 3.0 : 0.0;
      direct[p] += seen * n_dot / 3.0;
    }
  }
  EXPECT_EQ(got.steps, steps);
  EXPECT_LT(got.sweeps, steps);
  std::printf("insolation: %d steps with the sun up in %d sweeps\n", got.steps, got.sweeps);
  int off = 0;
  double sum = 0.0, expected_sum = 0.0, hours_off = 0.0;
  for (std::size_t p = 0; p < field.pixelCount(); ++p) {
    if (std::isnan(heights[p])) {
      EXPECT_TRUE(std::isnan(got.sun_hours[p]) && std::isnan(got.direct[p]));
      continue;
    }
    off += std::fabs(got.sun_hours[p] - hours[p]) > 1.0 + 1e-4;  // a step a day
    hours_off += std::fabs(got.sun_hours[p] - hours[p]);
    sum += got.direct[p];
    expected_sum += direct[p];
  }
  std::printf("insolation: sun hours %.4f h off on the mean, %d pixels more than a step a day off\n",
              hours_off / (field.pixelCount() - 1), off);
  EXPECT_LE(off, static_cast<int>(field.pixelCount() / 100)) << "pixels more than a step a day off";
  EXPECT_LT(hours_off / (field.pixelCount() - 1), 0.05);
  EXPECT_NEAR(sum / expected_sum, 1.0, 0.01);
  EXPECT_GT(expected_sum / field.pixelCount(), 15.0);  // hours of unit sun: three long summer days
}

TEST(Insolation, RefusesBadOptions) {
  const HeightField flat = makeSyntheticField("flat", 5, 5);
  InsolationOptions o;
  o.from_utc = parseUtcTime("2026-06-21T00:00:00Z");
  o.to_utc = o.from_utc;  // empty span
  EXPECT_THROW(computeInsolation(testContext(), flat, o), InvalidArgument);
  // (the message named no value and ended "from before to")
  try {
    o.to_utc = o.from_utc - 60.0;
    computeInsolation(testContext(), flat, o);
    ADD_FAILURE() << "a span backwards ran";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("got 1.782e+09 to 1.78199994e+09 seconds since 1970"),
              std::string::npos)
        << e.what();
  }
  o.to_utc = o.from_utc + 3600.0;
  o.step_minutes = 0.0;
  EXPECT_THROW(computeInsolation(testContext(), flat, o), InvalidArgument);
  o.step_minutes = 10.0;
  o.azimuth_bucket_deg = 20.0;
  EXPECT_THROW(computeInsolation(testContext(), flat, o), InvalidArgument);
  // (a bucket's index is the azimuth over it: 1e-30 degrees put every step in one bucket)
  for (const double tiny : {1e-30, 1e-17, 0.0009}) {
    o.azimuth_bucket_deg = tiny;
    EXPECT_THROW(computeInsolation(testContext(), flat, o), InvalidArgument) << tiny;
  }
  o.azimuth_bucket_deg = 0.25;
  // The span is [from, to): it may end as 2201 begins (its excluded end was refused), not after.
  o.from_utc = parseUtcTime("2200-12-31T00:00:00Z");
  o.to_utc = parseUtcTime("2201-01-01T00:00:00Z");
  o.step_minutes = 60.0;
  EXPECT_NO_THROW(computeInsolation(testContext(), flat, o));
  o.to_utc += 1.0;
  EXPECT_THROW(computeInsolation(testContext(), flat, o), InvalidArgument);
  o.to_utc -= 1.0;
  o.latitude_deg = 91.0;
  EXPECT_THROW(computeInsolation(testContext(), flat, o), InvalidArgument);
}

}  // namespace

}  // namespace hfvis
