// test_horizon_lists.cpp: the visibility horizons of chosen receivers (hfvis/horizon_lists.hpp)
// against a brute-force enumeration on the same ray samples (visibility by definition, the
// horizons of Eq. 1 and 2, the segments by definition), against the naive visibility kernel
// (the same ray, sample for sample) and the tree's per-pixel counts on the axes, against the
// horizon operation (the farthest horizon is the horizon), and on an analytic wall.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "core/chord_side.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/horizon_lists.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis_testing/horizon_lists_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "core/horizon_common.hpp"
#include "core/sweep_geometry.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::awkwardSizes;
using testing::fieldFrom;
using testing::testContext;

// The lists of one receiver and direction against brute force.
void expectListEqualsBruteForce(const DirectionHorizons& list, const std::vector<float>& ray, float hr) {
  const HorizonListReference expected = referenceHorizonList(ray, hr);
  ASSERT_EQ(list.ray_samples, static_cast<int>(ray.size()));
  std::vector<int> horizons;
  for (const auto& h : list.horizons) horizons.push_back(h.sample);
  ASSERT_EQ(horizons, expected.horizons);
  int total = 0;
  for (bool v : expected.visible) total += v;
  ASSERT_EQ(list.visible_samples, total);
  std::vector<bool> covered(ray.size() + 1, false);
  int previous = 0;  // the next nearer horizon's sample
  double previous_elevation = -M_PI;
  for (const VisibilityHorizon& h : list.horizons) {
    SCOPED_TRACE("horizon at sample " + std::to_string(h.sample));
    ASSERT_TRUE(expected.visible[h.sample]);
    ASSERT_DOUBLE_EQ(h.distance, h.sample * list.sample_spacing);
    ASSERT_DOUBLE_EQ(h.elevation, std::atan2(double(ray[h.sample - 1]) - hr, h.distance));
    ASSERT_GE(h.elevation, previous_elevation - 1e-12);
    previous_elevation = h.elevation;
    ASSERT_EQ(h.segment_end, h.sample + 1);
    ASSERT_GT(h.segment_begin, previous);
    ASSERT_DOUBLE_EQ(h.near_distance, h.segment_begin * list.sample_spacing);
    // The segment: every present sample in it is visible, it starts right after a hidden
    // present sample or at the next nearer horizon (or at sample 1), and nothing visible
    // between the next horizon and it is left out.
    int present = 0;
    for (int i = h.segment_begin; i <= h.sample; ++i) {
      if (std::isnan(ray[i - 1])) continue;
      ASSERT_TRUE(expected.visible[i]) << "sample " << i << " in the segment is hidden";
      ASSERT_FALSE(covered[i]);
      covered[i] = true;
      ++present;
    }
    ASSERT_EQ(h.visible_samples, present);
    ASSERT_FALSE(std::isnan(ray[h.segment_begin - 1])) << "a segment begins with a present sample";
    previous = h.sample;
  }
  for (std::size_t i = 1; i < covered.size(); ++i)
    ASSERT_EQ(covered[i], bool(expected.visible[i])) << "sample " << i;
}

TEST(HorizonLists, EqualBruteForceOnEveryHardCase) {
  int checked = 0;
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      HeightField field = makeSyntheticField(name, w, h, 5);
      field.cell_size_x = 1.5;
      SweepOptions options;
      options.directions = 8;
      options.azimuth_offset = 0.2;
      options.samples_per_unit = name == "sine" ? 2.5 : 1.0;
      std::vector<ReceiverPixel> receivers;
      for (int r = 0; r < h; r += std::max(1, h / 4))
        for (int c = 0; c < w; c += std::max(1, w / 5)) receivers.push_back({c, r});
      const auto lists = computeHorizonLists(field, options, receivers);
      const auto prepared = detail::prepareHeights(field);
      const auto directions = detail::runDirections(field, options);
      ASSERT_EQ(lists.size(), receivers.size());
      for (std::size_t n = 0; n < receivers.size(); ++n) {
        const auto [c, r] = receivers[n];
        const float hr = prepared.heights[std::size_t(r) * w + c];
        ASSERT_EQ(lists[n].nodata, std::isnan(hr));
        ASSERT_EQ(lists[n].directions.size(), 8u);
        for (int k = 0; k < 8; ++k) {
          SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " receiver (" +
                       std::to_string(c) + ", " + std::to_string(r) + ") direction " + std::to_string(k));
          const DirectionHorizons& list = lists[n].directions[k];
          EXPECT_EQ(list.direction, k);
          EXPECT_DOUBLE_EQ(list.azimuth, directionAzimuth(k, options));
          const auto ray = referenceRay(field, prepared.heights, directions[k], c, r);
          if (std::isnan(hr)) {
            ASSERT_TRUE(list.horizons.empty());
            continue;
          }
          expectListEqualsBruteForce(list, ray, hr);
          if (::testing::Test::HasFatalFailure()) return;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 2000);
}

// Every direction: the lists' visible samples equal the naive visibility kernel's count
// for that direction alone (a run of K = 1 at that azimuth marches the same ray); on the
// axis directions also the tree sweep's per-pixel count (lines through pixel centres). Flat
// and over a curved Earth (a drop of several height units across the field); also on rows of
// their own spacing (positions in ground units, as the kernels take them).
void expectListsAgreeWithTheKernels(double curvature, bool row_spacing = false) {
  SCOPED_TRACE("curvature " + std::to_string(curvature) + (row_spacing ? ", rows of their own spacing" : ""));
  HeightField field = makeSyntheticField("noise", 33, 20, 8);
  if (row_spacing) testing::setRowSpacing(field);
  SweepOptions options;
  options.directions = 8;
  options.azimuth_offset = 0.0;
  options.curvature = curvature;
  std::vector<ReceiverPixel> receivers;
  for (int r = 0; r < field.height; r += 3)
    for (int c = 0; c < field.width; c += 4) receivers.push_back({c, r});
  const auto lists = computeHorizonLists(field, options, receivers);
  IntervisibilityOutputs counts;
  counts.visible_count = true;
  std::vector<float> tree_axes(field.pixelCount(), 0.0f);
  for (int k = 0; k < options.directions; ++k) {
    IntervisibilityOptions one;
    one.directions = 1;
    one.azimuth_offset = directionAzimuth(k, options);
    one.method = IntervisibilityMethod::Naive;
    one.curvature = curvature;
    const auto naive = computeIntervisibility(testContext(), field, one, counts);
    for (std::size_t n = 0; n < receivers.size(); ++n) {
      const std::size_t p = std::size_t(receivers[n].row) * field.width + receivers[n].col;
      EXPECT_EQ(float(lists[n].directions[k].visible_samples), naive.visible_count[p])
          << "receiver " << n << " direction " << k;
    }
  }
  IntervisibilityOptions axes;
  axes.directions = 4;
  axes.curvature = curvature;
  const auto tree = computeIntervisibility(testContext(), field, axes, counts);
  for (std::size_t n = 0; n < receivers.size(); ++n) {
    int sum = 0;
    for (int k = 0; k < 8; k += 2) sum += lists[n].directions[k].visible_samples;  // 0, 90, 180, 270 deg
    EXPECT_EQ(float(sum), tree.visible_count[std::size_t(receivers[n].row) * field.width + receivers[n].col]);
  }
}

TEST(HorizonLists, AgreeWithTheNaiveKernelAndTheTreeOnTheAxes) {
  expectListsAgreeWithTheKernels(0.0);
  expectListsAgreeWithTheKernels(0.004);
  expectListsAgreeWithTheKernels(0.0, true);
  expectListsAgreeWithTheKernels(0.004, true);
}

// The farthest horizon is the horizon of docs/CONVENTIONS.md (the largest elevation, the farther on
// ties): it equals the naive horizon march's elevation (up to its fast atan).
TEST(HorizonLists, FarthestHorizonIsTheHorizon) {
  const HeightField field = makeSyntheticField("sine", 40, 41, 1);
  HorizonOptions options;
  options.directions = 12;
  options.azimuth_offset = 0.1;
  options.method = HorizonMethod::Naive;
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  const auto horizons = computeHorizons(testContext(), field, options, outputs);
  std::vector<ReceiverPixel> receivers;
  for (int r = 1; r < 40; r += 5)
    for (int c = 2; c < 39; c += 6) receivers.push_back({c, r});
  const auto lists = computeHorizonLists(field, options, receivers);
  int compared = 0;
  for (std::size_t n = 0; n < receivers.size(); ++n) {
    for (int k = 0; k < options.directions; ++k) {
      const auto& list = lists[n].directions[k];
      const std::size_t p = std::size_t(k) * field.pixelCount() +
                            std::size_t(receivers[n].row) * field.width + receivers[n].col;
      if (list.horizons.empty()) {
        EXPECT_FLOAT_EQ(horizons.angles[p], -M_PI / 2);
        continue;
      }
      EXPECT_NEAR(list.horizons.back().elevation, horizons.angles[p], 2e-6) << n << " " << k;
      ++compared;
    }
  }
  EXPECT_GT(compared, 500);
}

// Analytic: level ground with a wall 100 high at column 10. From column 3 looking toward
// +x (k = 0), one horizon: the wall top, 7 away, whose segment holds the ground up to it
// (grazing ground is visible) and itself; the ground behind the wall is hidden. Looking
// toward -x (k = 2), the farthest ground sample, 3 away, with the whole ray.
TEST(HorizonLists, WallAnalytic) {
  const int w = 21;
  std::vector<float> heights(w * 5, 0.0f);
  for (int r = 0; r < 5; ++r) heights[r * w + 10] = 100.0f;
  HeightField field = fieldFrom(w, 5, heights);
  field.cell_size_x = 2.0;
  SweepOptions options;
  options.directions = 4;
  const auto lists = computeHorizonLists(field, options, {{3, 2}});
  ASSERT_EQ(lists.size(), 1u);
  const auto& toward = lists[0].directions[0];
  ASSERT_EQ(toward.horizons.size(), 1u);
  EXPECT_EQ(toward.ray_samples, 17);
  EXPECT_EQ(toward.visible_samples, 7);
  const VisibilityHorizon& wall = toward.horizons[0];
  EXPECT_EQ(wall.sample, 7);
  EXPECT_DOUBLE_EQ(wall.distance, 14.0);
  EXPECT_DOUBLE_EQ(wall.elevation, std::atan2(100.0, 14.0));
  EXPECT_EQ(wall.segment_begin, 1);
  EXPECT_EQ(wall.segment_end, 8);
  EXPECT_DOUBLE_EQ(wall.near_distance, 2.0);
  const auto& away = lists[0].directions[2];
  ASSERT_EQ(away.horizons.size(), 1u);
  EXPECT_EQ(away.horizons[0].sample, 3);
  EXPECT_DOUBLE_EQ(away.horizons[0].elevation, 0.0);
  EXPECT_EQ(away.horizons[0].visible_samples, 3);
  // Along the column (k = 1: +row) the ray has 2 samples, both level.
  EXPECT_EQ(lists[0].directions[1].visible_samples, 2);
  // With a spacing per row (row 2's east-west cells 3 long, the others' 1), the wall lies
  // 7 x 3 away from row 2 (positions in whole units of ground length: each step within a
  // relative 2^-24 (W + H + 181) = 1.2e-5).
  field.row_cell_size_x = {1.0, 1.0, 3.0, 1.0, 1.0};
  field.row_cell_size_y = {1.0, 1.0, 1.0, 1.0, 1.0};
  field.cell_size_x = 3.0;
  field.cell_size_y = 1.0;
  const auto rows = computeHorizonLists(field, options, {{3, 2}, {3, 1}});
  ASSERT_EQ(rows[0].directions[0].horizons.size(), 1u);
  EXPECT_NEAR(rows[0].directions[0].horizons[0].distance, 21.0, 21.0 * 1.3e-5);
  EXPECT_NEAR(rows[0].directions[0].horizons[0].near_distance, 3.0, 3.0 * 1.3e-5);
  EXPECT_NEAR(rows[0].directions[0].sample_spacing, 3.0, 3.0 * 1.3e-5);
  EXPECT_NEAR(rows[0].directions[0].horizons[0].elevation, std::atan2(100.0, 21.0), 1e-6);
  EXPECT_NEAR(rows[1].directions[0].horizons[0].distance, 7.0, 7.0 * 1.3e-5);
}

TEST(HorizonLists, NodataAndBadReceivers) {
  const HeightField field = makeSyntheticField("nan_holes", 12, 10, 3);
  int hole = -1;
  for (std::size_t p = 0; p < field.pixelCount() && hole < 0; ++p)
    if (std::isnan(field.heights[p])) hole = static_cast<int>(p);
  ASSERT_GE(hole, 0);
  SweepOptions options;
  options.directions = 4;
  const auto lists = computeHorizonLists(field, options, {{hole % 12, hole / 12}});
  EXPECT_TRUE(lists[0].nodata);
  EXPECT_TRUE(std::isnan(lists[0].height));
  for (const auto& d : lists[0].directions) {
    EXPECT_TRUE(d.horizons.empty());
    EXPECT_EQ(d.visible_samples, 0);
  }
  EXPECT_THROW(computeHorizonLists(field, options, {{12, 0}}), InvalidArgument);
  EXPECT_THROW(computeHorizonLists(field, options, {{0, -1}}), InvalidArgument);
  options.directions = 0;
  EXPECT_THROW(computeHorizonLists(field, options, {{0, 0}}), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
