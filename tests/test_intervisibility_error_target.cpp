// test_intervisibility_error_target.cpp: the visible count's and area's relative error estimate
// (IntervisibilityOutputs::error_estimate) and the runs that choose K for a maximum error
// (IntervisibilityOptions::max_error): the kernels against the scalar reference in both buffer
// layouts (strips, per-row spacing, a maximum distance), the halves' arithmetic, the estimate
// against a dense run, and bad requests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "core/hull_tree.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis_testing/intervisibility_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::nearlyEqual;
using testing::testContext;

IntervisibilityOutputs estimated() {
  IntervisibilityOutputs outputs;
  outputs.visible_count = outputs.visible_area = outputs.error_estimate = true;
  return outputs;
}

// The halves' arithmetic: each half over its own wedges estimates the whole count, the estimate is
// their difference relative to the field's mean total count, NaN at nodata; the count and the area
// are the halves' totals.
TEST(IntervisibilityErrorEstimate, HalvesSplitAsDocumented) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  IntervisibilityResult r;
  r.width = 4;
  r.height = 1;
  r.visible_count = {10.0f, 0.0f, nan, 8.0f};
  r.visible_area = {100.0f, 0.0f, nan, 30.0f};
  // Even wedges 0.5, odd 0.5. Total counts 16, 0, 16: mean 32 / 3. Pixel 0: halves 20 and 12,
  // difference 8, relative 8 / (32 / 3) = 0.75; pixel 1 sees nothing (0); pixel 3: 16 and 16 (0).
  detail::splitVisibilityHalves(r, {6.0f, 0.0f, nan, 8.0f}, {50.0f, 0.0f, nan, 10.0f}, 0.5, 0.5);
  EXPECT_NEAR(r.error_estimate[0], 0.75, 1e-6);
  EXPECT_EQ(r.error_estimate[1], 0.0f);
  EXPECT_TRUE(std::isnan(r.error_estimate[2]));
  EXPECT_EQ(r.error_estimate[3], 0.0f);
  EXPECT_EQ(r.visible_count[0], 16.0f);
  EXPECT_EQ(r.visible_area[0], 150.0f);
  EXPECT_EQ(r.visible_area[3], 40.0f);
  // Unequal halves (odd K): each normalised by its own wedges. Even 3/7, odd 4/7: a pixel whose
  // directions all see the same per wedge has no error. Without the area, only the count.
  IntervisibilityResult odd_k;
  odd_k.width = odd_k.height = 1;
  odd_k.visible_count = {3.0f};
  detail::splitVisibilityHalves(odd_k, {4.0f}, {}, 3.0 / 7.0, 4.0 / 7.0);
  EXPECT_NEAR(odd_k.error_estimate[0], 0.0, 1e-6);
  EXPECT_EQ(odd_k.visible_count[0], 7.0f);
  EXPECT_TRUE(odd_k.visible_area.empty());
}

// The device path against the scalar reference (the same sums in the same order, then the same
// split): every hard case, odd and even K, in both layouts; and the paths the hard cases do not
// take (per-row spacing, a maximum distance, strips).
TEST(IntervisibilityErrorEstimate, KernelMatchesTheScalarReference) {
  testing::forEachLayout([](const ComputeContext& context) {
    for (int K : {7, 8}) {
      IntervisibilityOptions options;
      options.directions = K;
      options.azimuth_offset = 0.1;
      testing::forEachHardCase([&](const std::string&, const HeightField& field) {
        const IntervisibilityResult device = computeIntervisibility(context, field, options, estimated());
        const IntervisibilityResult reference = referenceIntervisibility(field, options, estimated());
        EXPECT_TRUE(nearlyEqual(device.visible_count, reference.visible_count, 0.0f));
        EXPECT_TRUE(nearlyEqual(device.visible_area, reference.visible_area, 0.0f));
        EXPECT_TRUE(nearlyEqual(device.error_estimate, reference.error_estimate, 0.0f));
        EXPECT_EQ(device.estimated_error, reference.estimated_error);
      });
    }
    for (const char* name : {"city", "nan_holes"}) {
      HeightField field = makeSyntheticField(name, 37, 29, 5);
      HeightField rows = field;
      testing::setRowSpacing(rows);
      for (const HeightField* f : {&field, &rows}) {
        for (double max_distance : {0.0, 6.5}) {
          SCOPED_TRACE(std::string(name) + (f == &rows ? " per-row spacing" : "") + " max distance " +
                       std::to_string(max_distance));
          IntervisibilityOptions options;
          options.directions = 16;
          options.max_distance = max_distance;
          const IntervisibilityResult reference = referenceIntervisibility(*f, options, estimated());
          EXPECT_GT(reference.estimated_error, 0.0);
          for (int strip_rows : {0, 6}) {
            options.strip_rows = strip_rows;
            const IntervisibilityResult device = computeIntervisibility(context, *f, options, estimated());
            EXPECT_TRUE(nearlyEqual(device.visible_count, reference.visible_count, 0.0f)) << strip_rows;
            EXPECT_TRUE(nearlyEqual(device.visible_area, reference.visible_area, 0.0f)) << strip_rows;
            EXPECT_TRUE(nearlyEqual(device.error_estimate, reference.error_estimate, 0.0f)) << strip_rows;
          }
        }
      }
    }
  });
}

// The estimate leaves the count and area as a run without it (up to the order the sums are added
// in), also where steps merge (K = 2048 on a small field: each half keeps its wedges), and asked
// with the area alone it still estimates from the count.
TEST(IntervisibilityErrorEstimate, OutputsUnchangedByTheEstimate) {
  const HeightField field = makeSyntheticField("city", 40, 36);
  for (int K : {24, 2048}) {
    SCOPED_TRACE(K);
    IntervisibilityOptions options;
    options.directions = K;
    IntervisibilityOutputs plain;
    plain.visible_count = plain.visible_area = true;
    const IntervisibilityResult without = computeIntervisibility(testContext(), field, options, plain);
    const IntervisibilityResult with = computeIntervisibility(testContext(), field, options, estimated());
    for (std::size_t p = 0; p < without.visible_count.size(); ++p) {
      ASSERT_NEAR(with.visible_count[p], without.visible_count[p], 1e-5 * without.visible_count[p]) << p;
      ASSERT_NEAR(with.visible_area[p], without.visible_area[p], 1e-5 * without.visible_area[p]) << p;
    }
    EXPECT_GT(with.estimated_error, 0.0);
  }
  IntervisibilityOptions options;
  options.directions = 16;
  IntervisibilityOutputs area_only;
  area_only.visible_area = area_only.error_estimate = true;
  const IntervisibilityResult area = computeIntervisibility(testContext(), field, options, area_only);
  const IntervisibilityResult both = computeIntervisibility(testContext(), field, options, estimated());
  EXPECT_TRUE(area.visible_count.empty());
  EXPECT_TRUE(nearlyEqual(area.error_estimate, both.error_estimate, 0.0f));
}

// The estimate's calibration on hard cases: as K doubles it falls, and at each K it lies at or
// above the count's error against a dense run (K = 1024) relative to its mean, the pixels' 99th
// percentile (half the halves' difference, as the sky-view factor takes, lies below it at K = 32
// .. 256 on both fields: this test fails with it).
TEST(IntervisibilityErrorEstimate, FallsAsKDoublesAndBoundsTheErrorAgainstADenseRun) {
  for (const char* name : {"noise", "city"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 64, 60);
    IntervisibilityOptions options;
    options.directions = 1024;
    IntervisibilityOutputs plain;
    plain.visible_count = plain.visible_area = true;
    const IntervisibilityResult truth = computeIntervisibility(testContext(), field, options, plain);
    double last = 1e9;
    for (int K : {16, 32, 64, 128, 256}) {
      SCOPED_TRACE(K);
      options.directions = K;
      const IntervisibilityResult r = computeIntervisibility(testContext(), field, options, estimated());
      EXPECT_LT(r.estimated_error, last);
      EXPECT_GE(r.estimated_error, countErrorP99(r, truth));
      last = r.estimated_error;
    }
  }
}

// A maximum error: the K chosen meets it by the estimate and against a dense run (K = 1024), a
// smaller error never takes fewer directions nor gives a larger estimate, and the runs it made
// start at 16 and grow to the K returned.
TEST(IntervisibilityMaxError, MeetsTheTargetAgainstADenseRun) {
  for (const char* name : {"noise", "city"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 64, 60);
    IntervisibilityOptions dense;
    dense.directions = 1024;
    IntervisibilityOutputs plain;
    plain.visible_count = plain.visible_area = true;
    const IntervisibilityResult truth = computeIntervisibility(testContext(), field, dense, plain);
    int last_directions = 0;
    double last_estimate = 1.0;
    for (double E : {0.3, 0.15}) {
      SCOPED_TRACE(E);
      IntervisibilityOptions options;
      options.max_error = E;
      const IntervisibilityResult r = computeIntervisibility(testContext(), field, options, plain);
      EXPECT_LE(r.estimated_error, E);
      EXPECT_LE(countErrorP99(r, truth), E);
      EXPECT_GE(r.directions, last_directions);
      EXPECT_LE(r.estimated_error, last_estimate);
      EXPECT_EQ(r.error_estimate.size(), field.pixelCount());
      ASSERT_FALSE(r.runs.empty());
      EXPECT_EQ(r.runs.front(), 16);
      EXPECT_EQ(r.runs.back(), r.directions);
      EXPECT_TRUE(std::is_sorted(r.runs.begin(), r.runs.end(), std::less_equal<int>()));
      // The K returned run with -k gives the same count.
      options.max_error = 0.0;
      options.directions = r.directions;
      EXPECT_TRUE(
          nearlyEqual(computeIntervisibility(testContext(), field, options, estimated()).visible_count,
                      r.visible_count, 0.0f));
      last_directions = r.directions;
      last_estimate = r.estimated_error;
    }
  }
}

TEST(IntervisibilityMaxError, BadRequestsAreRefused) {
  const HeightField field = makeSyntheticField("noise", 16, 16);
  IntervisibilityOutputs count;
  count.visible_count = true;
  IntervisibilityOptions options;
  for (double E :
       {-0.01, 1.0, 2.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    options.max_error = E;
    EXPECT_THROW(computeIntervisibility(testContext(), field, options, count), InvalidArgument) << E;
  }
  options.max_error = 0.01;
  options.method = IntervisibilityMethod::Naive;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, count), InvalidArgument);
  options.method = IntervisibilityMethod::HullTree;
  // Beyond kMaxAutoDirections by a run's prediction.
  options.max_error = 1e-7;
  try {
    computeIntervisibility(testContext(), field, options, count);
    ADD_FAILURE() << "an error of 1e-7 was accepted";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("directions"), std::string::npos) << error.what();
  }
  options.max_error = 0.0;
  options.directions = 1;
  IntervisibilityOutputs one = count;
  one.error_estimate = true;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, one), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
