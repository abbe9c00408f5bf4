// test_horizon_angle_error.cpp: "ask for an error" for the horizon angles (HorizonOptions::max_error
// with the horizon planes, core/horizon_angle_error.hpp): the interpolation error and its
// estimate in closed form, the estimate against a dense run, the runs that choose K, and bad
// requests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "core/horizon_angle_error.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/sweep_options.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::testContext;

HorizonOutputs angles(bool estimate = false) {
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  outputs.error_estimate = estimate;
  return outputs;
}

HorizonResult planesAt(const HeightField& field, int K, bool estimate = false) {
  HorizonOptions options;
  options.directions = K;
  return computeHorizons(testContext(), field, options, angles(estimate));
}

// The dense run the errors are measured against: K = 1024 at an azimuth tolerance of 0.02 degrees
// (its directions apart, not the run's own steps; as bench/error_target.cpp's reference).
HorizonResult denseRun(const HeightField& field) {
  HorizonOptions options;
  options.directions = 1024;
  options.azimuth_tolerance = 0.02 * M_PI / 180.0;
  return computeHorizons(testContext(), field, options, angles());
}

// A one-pixel result of K evenly spaced azimuths (offset by `offset`) whose planes are h(k).
HorizonResult onePixel(int K, const std::function<float(int)>& h, double offset = 0.0) {
  HorizonResult r;
  r.width = r.height = 1;
  r.directions = K;
  for (int k = 0; k < K; ++k) {
    r.azimuths.push_back(2.0 * M_PI * k / K + offset);
    r.angles.push_back(h(k));
  }
  return r;
}

// One spike among zeros: skipping one, the spike is missed by 1 and each neighbour is
// interpolated half-way up it (0.5); skipping two, the spike by 1 and the directions two places
// away by 0.5 (those one place away interpolate between zeros): means over K of those. A
// constant horizon interpolates exactly.
TEST(HorizonAngleError, SkipErrorsOfASpikeHaveTheClosedForm) {
  const int K = 16;
  const HorizonResult r = onePixel(K, [](int k) { return k == 5 ? 1.0f : 0.0f; }, 0.3);
  const detail::SkipErrors skips = detail::horizonSkipErrors(r);
  EXPECT_NEAR(skips.skip_one[0], 2.0 / K, 1e-6);
  EXPECT_NEAR(skips.skip_two[0], 2.0 / K, 1e-6);
  const HorizonResult flat = onePixel(K, [](int) { return 0.25f; });
  EXPECT_EQ(detail::horizonSkipErrors(flat).skip_one[0], 0.0f);
}

// The order is the directions' in azimuth, whatever order the run gives them in (snapped steps
// may swap neighbours) and each step once (coinciding steps share their plane).
TEST(HorizonAngleError, AzimuthOrderSortsAndMergesCoincidingSteps) {
  const detail::AzimuthOrder order = detail::azimuthOrder({0.5, 0.2, 0.2, 2.0 * M_PI + 0.1, -0.5});
  ASSERT_EQ(order.index.size(), 4u);
  EXPECT_EQ(order.index, (std::vector<int>{3, 1, 0, 4}));
  EXPECT_NEAR(order.azimuth[0], 0.1, 1e-12);
  EXPECT_NEAR(order.azimuth[3], 2.0 * M_PI - 0.5, 1e-12);
}

// Against a reference: at the reference's azimuths the result's interpolation; a result holding
// the reference's every other direction misses the spike by half its weight share, and the
// reference against itself by nothing.
TEST(HorizonAngleError, ErrorAgainstAReferenceHasTheClosedForm) {
  const int K = 32;
  const HorizonResult reference = onePixel(K, [](int k) { return k == 7 ? 1.0f : 0.0f; });
  EXPECT_EQ(detail::horizonAngleErrorAgainst(reference, reference), 0.0);
  HorizonResult half = onePixel(K / 2, [](int) { return 0.0f; });  // k = 7 not among its azimuths
  EXPECT_NEAR(detail::horizonAngleErrorAgainst(half, reference), 1.0 / K, 1e-9);
}

// The estimate falls as K grows, field by field, and lies above the error against a dense run of
// the same sweep (K = 1024), in the mean over the pixels, on every field tried.
TEST(HorizonAngleError, EstimateFallsWithKAndBoundsTheErrorAgainstADenseRun) {
  for (const char* name : {"noise", "city", "sine", "terraces"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 48, 44);
    const HorizonResult dense = denseRun(field);
    double last = std::numeric_limits<double>::infinity();
    for (int K : {16, 32, 64, 128, 256}) {
      SCOPED_TRACE(K);
      const HorizonResult r = planesAt(field, K, true);
      ASSERT_EQ(r.error_estimate.size(), field.pixelCount());
      EXPECT_EQ(r.estimated_error, detail::meanWithData(r.error_estimate));
      EXPECT_LT(r.estimated_error, last);
      last = r.estimated_error;
      EXPECT_GE(r.estimated_error, detail::horizonAngleErrorAgainst(r, dense));
      // The planes are the run's without the estimate.
      EXPECT_EQ(r.angles, planesAt(field, K).angles);
    }
  }
  // Flat ground: every horizon the same (0) but on the edges, where the rays that leave the field
  // at once read -pi/2; nothing to estimate inside.
  const HorizonResult flat = planesAt(makeSyntheticField("flat", 20, 17), 16, true);
  for (int r = 1; r < 16; ++r)
    for (int c = 1; c < 19; ++c) ASSERT_EQ(flat.error_estimate[r * 20 + c], 0.0f) << c << " " << r;
  EXPECT_GT(flat.estimated_error, 0.0);
}

// Nodata stays out of the mean and is NaN in the per-pixel estimate.
TEST(HorizonAngleError, NodataIsNaNAndLeftOutOfTheMean) {
  const HeightField field = makeSyntheticField("nan_holes", 40, 36);
  const HorizonResult r = planesAt(field, 24, true);
  std::size_t holes = 0;
  for (std::size_t p = 0; p < field.pixelCount(); ++p)
    if (std::isnan(field.heights[p])) {
      ++holes;
      EXPECT_TRUE(std::isnan(r.error_estimate[p]));
    }
  ASSERT_GT(holes, 0u);
  EXPECT_TRUE(std::isfinite(r.estimated_error));
  EXPECT_GT(r.estimated_error, 0.0);
}

// The K run for a need: the multiple of 8 of least work from the need (rounded up) to 1.25 times
// it, the smallest of equals; and the sweep's work is not monotone in K (K = 64's directions take
// shorter steps than K = 40's), which is why.
TEST(HorizonAngleMaxError, RunsTheCheapestKWithinAQuarterAboveTheNeed) {
  const auto work = [](int K) { return K % 32 == 0 ? 0.5 * K : double(K); };
  EXPECT_EQ(detail::cheapestDirections(80, work), 96);    // of 80, 88, 96
  EXPECT_EQ(detail::cheapestDirections(100, work), 128);  // of 104 .. 128
  EXPECT_EQ(detail::cheapestDirections(40, work), 40);    // of 40, 48: none a multiple of 32
  EXPECT_EQ(detail::cheapestDirections(3, work), 8);
  EXPECT_EQ(detail::cheapestDirections(4096, work), 4096);
  const HeightField field = makeSyntheticField("noise", 32, 32);
  HorizonOptions options;
  EXPECT_LT(detail::horizonWork(field, options, angles(), 64), detail::horizonWork(field, options, angles(), 40));
  EXPECT_DOUBLE_EQ(detail::horizonWork(field, options, angles(), 24), planesAt(field, 24).samples_per_receiver);
}

// The runs toward a maximum error extend the last one where the directions that adds cost less than
// a fresh run (work linear in K here: always, where a multiple of the last K reaches the need), each
// extension handed the run before, and the work all runs' own directions: with an estimate of 1 / K
// and E = 0.01, 8, then 16, 32 (the third run at most twice as far) and 128 (the least multiple of 32
// past the need of about 105), each extending the one before, 128 directions' work in all.
TEST(HorizonAngleMaxError, ExtendsTheLastRunWhereItsNewDirectionsCostLess) {
  std::vector<std::pair<int, int>> calls;  // (K, the K extended or 0)
  const auto run = [&](int K, HorizonResult* from) {
    calls.emplace_back(K, from ? from->directions : 0);
    HorizonResult r;
    r.width = r.height = 1;
    r.directions = K;
    r.estimated_error = 1.0 / K;
    r.samples_per_receiver = K - (from ? from->directions : 0);
    return r;
  };
  std::map<int, int> asked;  // (each K's work asked for once)
  const HorizonResult r = detail::runHorizonAnglesToError(0.01, run, [&](int K) {
    ++asked[K];
    return double(K);
  });
  for (const auto& [K, times] : asked) EXPECT_EQ(times, 1) << "K = " << K;
  const std::vector<std::pair<int, int>> expected = {{8, 0}, {16, 8}, {32, 16}, {128, 32}};
  EXPECT_EQ(calls, expected);
  EXPECT_EQ(r.runs, (std::vector<int>{8, 16, 32, 128}));
  EXPECT_EQ(r.directions, 128);
  EXPECT_DOUBLE_EQ(r.samples_per_receiver, 128.0);
  // Where a multiple's new directions cost more than a fresh K, the fresh one runs: multiples of 32
  // cost half but 128 costs 200, so extending 32 to 128 adds 184 where a fresh 112 costs 112.
  calls.clear();
  const auto uneven = [](int K) { return K == 128 ? 200.0 : (K % 32 == 0 ? 0.5 * K : double(K)); };
  const HorizonResult fresh = detail::runHorizonAnglesToError(0.01, run, uneven);
  ASSERT_EQ(calls.size(), 4u);
  EXPECT_EQ(calls.back().second, 0);
  EXPECT_EQ(calls.back().first, 112);
  EXPECT_EQ(fresh.runs, (std::vector<int>{8, 16, 32, 112}));
  EXPECT_DOUBLE_EQ(fresh.samples_per_receiver, 8.0 + 8.0 + 16.0 + 112.0);  // (the fake's own counts)
}

// A direction two K share has one azimuth to the bit (directionAzimuth takes k / K in lowest terms),
// so that an extended run is the larger K's: every K a multiple of 8 up to 2048 against m K, m = 2 ..
// 8, with and without an offset (2 pi k / K as written differs in about one shared direction in seven).
TEST(HorizonAngleMaxError, SharedDirectionsHaveOneAzimuth) {
  for (const double offset : {0.0, 0.3}) {
    std::size_t shared = 0, differing = 0;
    for (int K = 8; K <= 2048; K += 8)
      for (int m = 2; m <= 8; ++m) {
        HorizonOptions small, large;
        small.directions = K, large.directions = m * K;
        small.azimuth_offset = large.azimuth_offset = offset;
        for (int k = 0; k < K; ++k, ++shared)
          differing += directionAzimuth(k, small) != directionAzimuth(m * k, large);
      }
    EXPECT_EQ(differing, 0u) << "of " << shared << " shared directions, offset " << offset;
  }
}

// An extended run (extendHorizonRun) from K = 8 to 8 m (m = 2, 3, 4, 6), its directions between
// K's cast in one run of a subset (computeHorizonDirections), with an azimuth offset and
// distances, against a fresh run at 8 m on a city and on noise: the planes and the azimuths bit
// for bit, the work the new directions'. And a subset alone: its directions in the order asked,
// each as the fresh run's.
TEST(HorizonAngleMaxError, AnExtendedRunIsAFreshRunsPlanes) {
  for (const char* name : {"city", "noise"}) {
    const HeightField field = makeSyntheticField(name, 40, 36);
    HorizonOutputs both = angles();
    both.horizon_distances = true;
    HorizonOptions options;
    options.azimuth_offset = 0.3;
    const auto at = [&](int K) {
      HorizonOptions o = options;
      o.directions = K;
      return computeHorizons(testContext(), field, o, both);
    };
    const HorizonResult eight = at(8);
    // (16 to 48 too: 2 pi k / K rounded apart for 16 and 48 at k = 11, 13 and 15 before the azimuths
    // took k / K in lowest terms)
    for (const auto& [base, m] : std::vector<std::pair<int, int>>{{8, 2}, {8, 3}, {8, 4}, {8, 6}, {16, 3}}) {
      SCOPED_TRACE(std::string(name) + " " + std::to_string(base) + " times " + std::to_string(m));
      const HorizonResult from = base == 8 ? eight : at(base);
      int runs = 0;
      const HorizonResult extended =
          detail::extendHorizonRun(from, base * m, [&](const std::vector<int>& indices) {
            ++runs;
            EXPECT_EQ(indices.size(), std::size_t(base * (m - 1)));
            return detail::computeHorizonDirections(testContext(), field, options, both, {base * m, indices});
          });
      EXPECT_EQ(runs, 1);
      const HorizonResult fresh = at(base * m);
      EXPECT_EQ(extended.directions, base * m);
      EXPECT_EQ(extended.angles, fresh.angles);
      EXPECT_EQ(extended.distances, fresh.distances);
      EXPECT_EQ(extended.azimuths, fresh.azimuths);
      EXPECT_NEAR(extended.samples_per_receiver, fresh.samples_per_receiver - from.samples_per_receiver,
                  1e-9 * fresh.samples_per_receiver);
    }
    // Directions 5, 1 and 6 of 8 (out of order): each the fresh run's plane and azimuth.
    const HorizonResult some = detail::computeHorizonDirections(testContext(), field, options, both, {8, {5, 1, 6}});
    ASSERT_EQ(some.directions, 3);
    const std::size_t plane = field.pixelCount();
    for (int i = 0; i < 3; ++i) {
      const int k = std::vector<int>{5, 1, 6}[std::size_t(i)];
      EXPECT_EQ(some.azimuths[std::size_t(i)], eight.azimuths[std::size_t(k)]);
      EXPECT_TRUE(std::equal(some.angles.begin() + i * plane, some.angles.begin() + (i + 1) * plane,
                             eight.angles.begin() + k * plane));
    }
  }
  EXPECT_THROW(detail::extendHorizonRun(HorizonResult(), 16, [](const std::vector<int>&) { return HorizonResult(); }),
               std::logic_error);
  // A subset is the sweep's horizon planes': the naive method, an index past the run's
  // directions and the sky-view factor are refused.
  const HeightField field = makeSyntheticField("noise", 24, 20);
  HorizonOptions naive;
  naive.method = HorizonMethod::Naive;
  EXPECT_THROW(detail::computeHorizonDirections(testContext(), field, naive, angles(), {16, {1, 3}}),
               std::logic_error);
  EXPECT_THROW(
      detail::computeHorizonDirections(testContext(), field, HorizonOptions(), angles(), {16, {1, 16}}),
      std::logic_error);
  HorizonOutputs svf;
  svf.sky_view_factor = true;
  EXPECT_THROW(detail::computeHorizonDirections(testContext(), field, HorizonOptions(), svf, {16, {1, 3}}),
               std::logic_error);
}

// A maximum error: the K chosen meets it by the estimate and against a dense run, its planes are
// those of a run at that K bit for bit, and a smaller error never takes fewer directions.
TEST(HorizonAngleMaxError, MeetsTheTargetAgainstADenseRun) {
  for (const char* name : {"noise", "city"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 48, 44);
    const HorizonResult dense = denseRun(field);
    int last_directions = 0, extended_cases = 0;
    for (double degrees : {2.0, 1.0, 0.5, 0.25}) {
      SCOPED_TRACE(degrees);
      const double E = degrees * M_PI / 180.0;
      HorizonOptions options;
      options.max_error = E;
      HorizonOutputs wanted = angles();
      wanted.horizon_distances = true;  // (computed at the K chosen)
      const HorizonResult r = computeHorizons(testContext(), field, options, wanted);
      EXPECT_LE(r.estimated_error, E);
      EXPECT_LE(detail::horizonAngleErrorAgainst(r, dense), E);
      ASSERT_FALSE(r.runs.empty());
      EXPECT_EQ(r.runs.front(), 8);
      EXPECT_EQ(r.runs.back(), r.directions);
      EXPECT_TRUE(std::is_sorted(r.runs.begin(), r.runs.end(), std::less<int>()));
      EXPECT_GE(r.directions, last_directions);
      last_directions = r.directions;
      ASSERT_EQ(r.angles.size(), field.pixelCount() * r.directions);
      EXPECT_EQ(r.distances.size(), r.angles.size());
      EXPECT_EQ(r.error_estimate.size(), field.pixelCount());
      // The planes and azimuths a run at that K gives, bit for bit, where the last run extended
      // an earlier one as where it ran afresh.
      HorizonOptions at_k;
      at_k.directions = r.directions;
      HorizonOutputs both = angles(true);
      both.horizon_distances = true;
      const HorizonResult fixed = computeHorizons(testContext(), field, at_k, both);
      EXPECT_EQ(r.angles, fixed.angles);
      EXPECT_EQ(r.distances, fixed.distances);
      EXPECT_EQ(r.azimuths, fixed.azimuths);
      EXPECT_EQ(r.estimated_error, fixed.estimated_error);  // (a one-run estimate: the same)
      // The work: each run's own directions, so that where every run extended the one before, all
      // of them together cost what the last K alone does.
      // (every run a multiple of the one before: on these fields each such run extended it)
      bool extended = r.runs.size() > 1;
      for (std::size_t i = 1; i < r.runs.size(); ++i) extended = extended && r.runs[i] % r.runs[i - 1] == 0;
      if (extended) {
        EXPECT_NEAR(r.samples_per_receiver, fixed.samples_per_receiver, 1e-9 * fixed.samples_per_receiver);
        ++extended_cases;
      }
    }
    EXPECT_GT(extended_cases, 0);  // (the extension is exercised)
  }
}

TEST(HorizonAngleMaxError, BadRequestsAreRefused) {
  const HeightField field = makeSyntheticField("noise", 24, 20);
  for (double E : {-0.01, std::nan(""), std::numeric_limits<double>::infinity(), M_PI / 2.0, 2.0}) {
    HorizonOptions options;
    options.max_error = E;
    EXPECT_THROW(computeHorizons(testContext(), field, options, angles()), InvalidArgument) << E;
  }
  HorizonOptions options;
  options.max_error = 0.01;
  // With the sky-view factor in the same run: whose error?
  HorizonOutputs both = angles();
  both.sky_view_factor = true;
  EXPECT_THROW(computeHorizons(testContext(), field, options, both), InvalidArgument);
  // Distances alone: the estimate is the angles'.
  HorizonOutputs distances;
  distances.horizon_distances = true;
  EXPECT_THROW(computeHorizons(testContext(), field, options, distances), InvalidArgument);
  // Tiles: K planes are one K for the whole field.
  options.error_tile = 8;
  EXPECT_THROW(computeHorizons(testContext(), field, options, angles()), InvalidArgument);
  // Beyond 4096 directions: refused, in degrees.
  options.error_tile = 0;
  options.max_error = 1e-7;
  try {
    computeHorizons(testContext(), field, options, angles());
    ADD_FAILURE() << "no error";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("degrees"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("4096"), std::string::npos) << error.what();
  }
  // An estimate at K given needs five directions.
  HorizonOptions few;
  few.directions = 4;
  EXPECT_THROW(computeHorizons(testContext(), field, few, angles(true)), InvalidArgument);
  few.directions = 5;
  EXPECT_NO_THROW(computeHorizons(testContext(), field, few, angles(true)));
}

}  // namespace
}  // namespace hfvis
