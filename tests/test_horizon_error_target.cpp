// test_horizon_error_target.cpp: the sky-view factor's and occlusion's error estimate
// (HorizonOutputs::error_estimate) and the runs that choose K for a maximum error
// (HorizonOptions::max_error): the kernels against the scalar reference in both buffer layouts,
// a closed form, strips, the estimate against a dense run, and bad requests.
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <functional>
#include <limits>
#include <map>

#include "core/horizon_common.hpp"
#include "core/lattice_geometry.hpp"
#include "hfvis/ambient_occlusion.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/sky_view_factor.hpp"
#include "hfvis_testing/horizon_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::nearlyEqual;
using testing::testContext;

HorizonOutputs estimated() {
  HorizonOutputs outputs;
  outputs.sky_view_factor = outputs.ambient_occlusion = outputs.error_estimate = true;
  return outputs;
}

// The 99th percentile of |a - b| over the pixels with data.
double p99Difference(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<double> d;
  for (std::size_t p = 0; p < a.size(); ++p)
    if (!std::isnan(a[p])) d.push_back(std::abs(static_cast<double>(a[p]) - b[p]));
  std::sort(d.begin(), d.end());
  return d.empty() ? 0.0 : d[std::min(d.size() - 1, static_cast<std::size_t>(0.99 * d.size()))];
}

// Odd K too: the halves then differ by one direction, each normalised by its own weights.
TEST(HorizonErrorEstimate, KernelsMatchTheScalarReferenceOnEveryHardCase) {
  testing::forEachLayout([](const ComputeContext& context) {
    for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
      for (int K : {7, 8}) {
        HorizonOptions options;
        options.method = method;
        options.directions = K;
        options.azimuth_offset = 0.1;
        testing::forEachHardCase([&](const std::string&, const HeightField& field) {
          const HorizonResult device = computeHorizons(context, field, options, estimated());
          const HorizonResult reference = referenceHorizons(field, options, estimated());
          const float tolerance = std::max(testing::divisionTolerance(), 2e-6f);
          EXPECT_TRUE(nearlyEqual(device.sky_view_factor, reference.sky_view_factor, tolerance));
          EXPECT_TRUE(nearlyEqual(device.ambient_occlusion, reference.ambient_occlusion, tolerance));
          EXPECT_TRUE(nearlyEqual(device.error_estimate, reference.error_estimate, tolerance));
          EXPECT_NEAR(device.estimated_error, reference.estimated_error, tolerance);
        });
      }
    }
  });
}

// The paths the hard cases above do not take: a maximum distance (the window's pass), a latitude /
// longitude grid (per-row spacing: each row's own quadrature weights), both at once, and strips of
// each, with nodata holes and odd K, against the scalar reference in both layouts.
TEST(HorizonErrorEstimate, WindowsRowSpacingAndStripsMatchTheScalarReference) {
  testing::forEachLayout([](const ComputeContext& context) {
    for (const char* name : {"city", "nan_holes"}) {
      HeightField field = makeSyntheticField(name, 37, 29, 5);
      HeightField rows = field;
      for (int r = 0; r < rows.height; ++r) {
        rows.row_cell_size_x.push_back(1.0 + 0.03 * r);
        rows.row_cell_size_y.push_back(1.1);
      }
      rows.cell_size_x = rows.row_cell_size_x[rows.height / 2];
      rows.cell_size_y = 1.1;
      for (const HeightField* f : {&field, &rows}) {
        for (double max_distance : {0.0, 6.5}) {
          for (int K : {9, 16}) {
            SCOPED_TRACE(std::string(name) + (f == &rows ? " per-row spacing" : "") + " max distance " +
                         std::to_string(max_distance) + " K " + std::to_string(K));
            HorizonOptions options;
            options.directions = K;
            options.max_distance = max_distance;
            const HorizonResult reference = referenceHorizons(*f, options, estimated());
            for (int strip_rows : {0, 6}) {
              options.strip_rows = strip_rows;
              const HorizonResult device = computeHorizons(context, *f, options, estimated());
              const float tolerance = std::max(testing::divisionTolerance(), 2e-6f);
              EXPECT_TRUE(nearlyEqual(device.sky_view_factor, reference.sky_view_factor, tolerance))
                  << strip_rows;
              EXPECT_TRUE(nearlyEqual(device.ambient_occlusion, reference.ambient_occlusion, tolerance))
                  << strip_rows;
              EXPECT_TRUE(nearlyEqual(device.error_estimate, reference.error_estimate, tolerance))
                  << strip_rows;
              EXPECT_NEAR(device.estimated_error, reference.estimated_error, tolerance) << strip_rows;
            }
          }
        }
      }
    }
  });
}

// The estimate leaves the outputs as a run without it (up to the order the sums are added in),
// and a field in strips gives the same estimate as in one piece, bit for bit.
TEST(HorizonErrorEstimate, OutputsUnchangedAndStripsEqualTheWholeField) {
  const HeightField field = makeSyntheticField("city", 48, 45);
  HorizonOptions options;
  options.directions = 24;
  HorizonOutputs plain;
  plain.sky_view_factor = plain.ambient_occlusion = true;
  const HorizonResult without = computeHorizons(testContext(), field, options, plain);
  const HorizonResult whole = computeHorizons(testContext(), field, options, estimated());
  EXPECT_TRUE(nearlyEqual(whole.sky_view_factor, without.sky_view_factor, 1e-5f));
  EXPECT_TRUE(nearlyEqual(whole.ambient_occlusion, without.ambient_occlusion, 1e-5f));
  EXPECT_GT(whole.estimated_error, 0.0);
  options.strip_rows = 7;
  const HorizonResult strips = computeHorizons(testContext(), field, options, estimated());
  EXPECT_TRUE(nearlyEqual(strips.sky_view_factor, whole.sky_view_factor, 0.0f));
  EXPECT_TRUE(nearlyEqual(strips.ambient_occlusion, whole.ambient_occlusion, 0.0f));
  EXPECT_TRUE(nearlyEqual(strips.error_estimate, whole.error_estimate, 0.0f));
}

// Street canyon (test_sky_view_factor.cpp): with K = 4 the even directions look across the street
// at the walls (sin of their elevation 4 / 5: SVF 0.2), the odd ones along it (level: SVF 1), so
// the estimate is half their difference, 0.4; flat ground estimates 0.
TEST(HorizonErrorEstimate, StreetCanyonAndFlatGroundHaveTheClosedForm) {
  const HeightField canyon = testing::streetCanyon(41, 61, 3, 4.0f);
  HorizonOptions options;
  options.directions = 4;
  for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
    options.method = method;
    const HorizonResult r = computeHorizons(testContext(), canyon, options, estimated());
    for (int row = 20; row <= 40; ++row) {
      EXPECT_NEAR(r.sky_view_factor[row * canyon.width + 20], 0.6, 1e-5) << row;
      EXPECT_NEAR(r.error_estimate[row * canyon.width + 20], 0.4, 1e-5) << row;
    }
  }
  const HorizonResult flat =
      computeHorizons(testContext(), makeSyntheticField("flat", 20, 17), options, estimated());
  for (float e : flat.error_estimate) ASSERT_EQ(e, 0.0f);
  EXPECT_EQ(flat.estimated_error, 0.0);
}

// A tilted plane sees all the sky above its tangent plane: occlusion 1. Eq. 5's swaths take the
// horizon as constant over each, and over the plane it varies smoothly with azimuth: the result
// lies (pi^2 / 6) w^2 sin^2(tilt) short of 1 (detail::swathBias), alike in the even and the odd
// directions, whose difference alone was the estimate (3e-5 at K = 16 where the error was 0.0023,
// and a maximum error of 0.002 stopped there: a probe's find). The estimate now holds the bias,
// and the maximum error is met against 1.
TEST(HorizonErrorEstimate, ATiltedPlanesOcclusionBiasIsInTheEstimate) {
  HeightField field = makeSyntheticField("flat", 33, 33);
  for (int r = 0; r < 33; ++r)
    for (int c = 0; c < 33; ++c) field.heights[r * 33 + c] = static_cast<float>(0.76 * (0.92 * c + 0.39 * r));
  const double sin2 =
      0.76 * 0.76 * (0.92 * 0.92 + 0.39 * 0.39) / (1.0 + 0.76 * 0.76 * (0.92 * 0.92 + 0.39 * 0.39));
  for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
    for (int K : {8, 16, 32}) {
      SCOPED_TRACE((method == HorizonMethod::Sweep ? "sweep K " : "naive K ") + std::to_string(K));
      HorizonOptions options;
      options.method = method;
      options.directions = K;
      const HorizonResult r = computeHorizons(testContext(), field, options, estimated());
      const std::size_t middle = 16 * 33 + 16;
      const double error = 1.0 - r.ambient_occlusion[middle];
      // The bias as predicted (within 10 %: the lattice's weights are not all 1 / K), and in the estimate.
      EXPECT_NEAR(error, detail::swathBias(sin2, 1.0 / (K * K)) / 1.15, 0.1 * error);
      for (int row = 4; row < 29; ++row)
        for (int c = 4; c < 29; ++c)
          EXPECT_GE(r.error_estimate[row * 33 + c], 1.0 - r.ambient_occlusion[row * 33 + c]);
    }
  }
  for (double max_error : {0.005, 0.002}) {
    HorizonOptions options;
    options.max_error = max_error;
    HorizonOutputs occlusion;
    occlusion.ambient_occlusion = true;
    const HorizonResult r = computeHorizons(testContext(), field, options, occlusion);
    std::vector<float> one(r.ambient_occlusion.size(), 1.0f);
    EXPECT_LE(p99Difference(r.ambient_occlusion, one), max_error) << max_error << " at K " << r.directions;
  }
}

// Beyond the lattice's angular resolution (K = 2048: neighbouring phi_k fall back to one step) the
// quadrature merges coinciding steps; for the estimate only within a parity, so that each half
// keeps the share of the circle its azimuths stand for (else one half loses the merged slots'
// weight and the halves differ by far more than the result's error).
TEST(HorizonErrorEstimate, MergedStepsStayInTheirHalf) {
  const HeightField field = makeSyntheticField("flat", 8, 8);
  HorizonOptions options;
  options.directions = 2048;
  for (bool parity_apart : {false, true}) {
    const auto directions = detail::latticeDirections(field, options, false, 0.0, parity_apart);
    double even = 0.0, odd = 0.0, largest_imbalance = 0.0;
    for (int k = 0; k < options.directions; ++k) {
      (k % 2 ? odd : even) += directions[k].weight;
      if (k % 64 == 63)
        largest_imbalance = std::max(largest_imbalance, std::abs(even - odd)), even = odd = 0.0;
    }
    // Over every 64 neighbouring directions the halves' weights agree to 5 % of their sum
    // (1/32) with parity_apart; without it some merged run puts the weight all on one side.
    if (parity_apart)
      EXPECT_LT(largest_imbalance, 0.05 / 32);
    else
      EXPECT_GT(largest_imbalance, 0.1 / 32);
  }
  // The run on the axis at azimuth 0 goes on from k = K - 1 to k = 0: with the azimuths turned by
  // 0.3 degree, k = 2045 .. 2048 fall on step (1, 0). Its slots share equally across the wrap, so
  // the 64 directions around k = 0 keep the halves' weights within 1 % of their sum (a scan from
  // k = 0 split the run in two, and gave the even half 1.3 slots of the odd one's: 5 %).
  options.azimuth_offset = 0.3 * M_PI / 180.0;
  const auto turned = detail::latticeDirections(field, options, false, 0.0, true);
  double even = 0.0, odd = 0.0;
  for (int j = -32; j < 32; ++j) {
    const int k = (j + options.directions) % options.directions;
    (k % 2 ? odd : even) += turned[k].weight;
  }
  EXPECT_LT(std::abs(even - odd), 0.01 / 32);
}

// A maximum error: the K chosen meets it by the estimate, the estimate lies above the error
// against a dense run (K = 1024) at the pixels' 99th percentile, a smaller error never takes
// fewer directions, and the estimate falls with it; refined in tiles, the error is met as well.
TEST(HorizonMaxError, MeetsTheTargetAgainstADenseRun) {
  for (const char* name : {"noise", "city"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 64, 60);
    HorizonOptions dense;
    dense.directions = 1024;
    const SkyViewFactorResult truth = computeSkyViewFactor(testContext(), field, dense);
    HorizonOutputs svf_only;
    svf_only.sky_view_factor = true;
    int last_directions = 0;
    double last_estimate = 1.0;
    for (double E : {0.05, 0.02, 0.01, 0.005}) {
      SCOPED_TRACE(E);
      HorizonOptions options;
      options.max_error = E;
      options.error_tile = 0;
      const SkyViewFactorResult r = computeSkyViewFactor(testContext(), field, options);
      EXPECT_LE(r.estimated_error, E);
      EXPECT_LE(p99Difference(r.values, truth.values), E);
      EXPECT_GE(r.directions, last_directions);
      EXPECT_LE(r.estimated_error, last_estimate);
      EXPECT_EQ(r.error_estimate.size(), field.pixelCount());
      // The runs it made: from the first K up, each at more directions, the last the one returned.
      const HorizonResult runs = computeHorizons(testContext(), field, options, svf_only);
      ASSERT_FALSE(runs.runs.empty());
      EXPECT_EQ(runs.runs.front(), 16);
      EXPECT_EQ(runs.runs.back(), r.directions);
      EXPECT_TRUE(std::is_sorted(runs.runs.begin(), runs.runs.end(), std::less_equal<int>()));
      for (int K : runs.pixel_directions) ASSERT_EQ(K, r.directions);
      last_directions = r.directions;
      last_estimate = r.estimated_error;
      options.error_tile = 16;
      const SkyViewFactorResult tiles = computeSkyViewFactor(testContext(), field, options);
      EXPECT_LE(tiles.estimated_error, E);
      EXPECT_LE(p99Difference(tiles.values, truth.values), E);
    }
    HorizonOptions options;
    options.max_error = 0.01;
    const AmbientOcclusionResult ao = computeAmbientOcclusion(testContext(), field, options);
    HorizonOutputs ao_only;
    ao_only.ambient_occlusion = true;
    EXPECT_LE(ao.estimated_error, 0.01);
    EXPECT_LE(
        p99Difference(ao.values, computeHorizons(testContext(), field, dense, ao_only).ambient_occlusion),
        0.01);
  }
}

// Open and dense parts in one field: the synthetic city with its right part levelled (0 there).
HeightField cityBesideFlat(const char* name, int width, int height) {
  HeightField field = makeSyntheticField(name, width, height);
  for (int r = 0; r < height; ++r)
    for (int c = width / 2; c < width; ++c) {
      float& h = field.heights[static_cast<std::size_t>(r) * width + c];
      if (!std::isnan(h)) h = 0.0f;
    }
  return field;
}

// Refinement in tiles (HorizonOptions::error_tile): every pixel's values are those of a whole-field
// run at the K it records (HorizonResult::pixel_directions), bit for bit, and its estimate that
// run's over one divisor per tile (the order its tile's runs measured), though the
// runs after the first sweep only the lines that reach their tiles (cut after them); the estimate
// meets E; the open part stops at fewer directions than the dense one, and the runs swept fewer
// receivers than whole-field runs at their K. On the city and nodata hard cases, in both
// buffer layouts, in one piece and in strips, and within a maximum distance.
TEST(HorizonMaxError, RefinedTilesEqualAWholeFieldRunAtTheirK) {
  testing::forEachLayout([](const ComputeContext& context) {
    for (const char* name : {"city", "nan_holes"}) {
      const HeightField field = cityBesideFlat(name, 41, 31);
      for (const auto& [strip_rows, max_distance] :
           {std::pair{0, 0.0}, std::pair{9, 0.0}, std::pair{0, 12.5}}) {
        SCOPED_TRACE(std::string(name) + " strip rows " + std::to_string(strip_rows) + " max distance " +
                     std::to_string(max_distance));
        HorizonOptions options;
        options.max_error = 0.02;
        options.error_tile = kMinErrorTile;
        options.strip_rows = strip_rows;
        options.max_distance = max_distance;
        HorizonOutputs both;
        both.sky_view_factor = both.ambient_occlusion = true;
        const HorizonResult refined = computeHorizons(context, field, options, both);
        ASSERT_EQ(refined.pixel_directions.size(), field.pixelCount());
        std::vector<int> taken = refined.pixel_directions;
        std::sort(taken.begin(), taken.end());
        taken.erase(std::unique(taken.begin(), taken.end()), taken.end());
        ASSERT_GE(taken.size(), 2u) << "no refinement to test";
        EXPECT_EQ(taken.back(), refined.directions);
        for (int K : taken) {
          SCOPED_TRACE(K);
          std::map<int, double> divisors;  // tile -> its estimate's divisor at K
          HorizonOptions fixed = options;
          fixed.max_error = 0.0;
          fixed.error_tile = 0;
          fixed.directions = K;
          const HorizonResult whole = computeHorizons(context, field, fixed, estimated());
          std::size_t compared = 0;
          for (std::size_t p = 0; p < field.pixelCount(); ++p) {
            if (refined.pixel_directions[p] != K) continue;
            const auto same = [](float x, float y) { return x == y || (std::isnan(x) && std::isnan(y)); };
            ASSERT_TRUE(same(refined.sky_view_factor[p], whole.sky_view_factor[p])) << p;
            ASSERT_TRUE(same(refined.ambient_occlusion[p], whole.ambient_occlusion[p])) << p;
            // The estimate: the run's raw one over its tile's divisor (richardsonDivisor: one per
            // tile and K, 1 .. 2^1.1 - 1).
            const int tile = static_cast<int>(p % field.width) / options.error_tile +
                             static_cast<int>(p / field.width) / options.error_tile * 100;
            if (std::isnan(whole.error_estimate[p]) || whole.error_estimate[p] == 0.0f) {
              ASSERT_TRUE(same(refined.error_estimate[p], whole.error_estimate[p])) << p;
            } else {
              const double divisor = whole.error_estimate[p] / static_cast<double>(refined.error_estimate[p]);
              ASSERT_GE(divisor, 1.0 - 1e-6) << p;
              ASSERT_LE(divisor, detail::richardsonDivisor(detail::kMaxRichardsonOrder) * (1 + 1e-6)) << p;
              // (the tiles' least and most divisor bound it)
              ASSERT_GE(divisor, refined.richardson_divisor_least * (1 - 1e-5)) << p;
              ASSERT_LE(divisor, refined.richardson_divisor_most * (1 + 1e-5)) << p;
              const auto [at, fresh] = divisors.emplace(tile, divisor);
              if (!fresh) {
                ASSERT_NEAR(divisor, at->second, 1e-5 * divisor) << p;
              }
            }
            ++compared;
          }
          EXPECT_GT(compared, 0u);
        }
        // The estimate's 99th percentile over the field meets E.
        EXPECT_LE(refined.estimated_error, options.max_error);
        // The levelled far corner needs fewer directions than the city's.
        EXPECT_LT(refined.pixel_directions[field.pixelCount() - 1], refined.directions);
        // The runs after the first swept fewer receivers than whole-field runs at their K would have.
        double whole_field_work = 0.0;
        for (int K : refined.runs) {
          HorizonOptions fixed = options;
          fixed.directions = K;
          for (const auto& d : detail::horizonDirections(field, fixed, estimated()))
            whole_field_work += static_cast<double>(detail::latticeSamples(d, fixed.samples_per_unit).size());
        }
        EXPECT_LT(refined.samples_per_receiver, whole_field_work);
      }
    }
  });
}

// The estimate's calibration on hard cases: as K doubles it falls, and at each K it lies at or above
// the error against a dense run (K = 1024), the pixels' 99th percentile, for both outputs.
TEST(HorizonErrorEstimate, FallsAsKDoublesAndBoundsTheErrorAgainstADenseRun) {
  for (const char* name : {"noise", "city"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 64, 60);
    for (bool ao : {false, true}) {
      SCOPED_TRACE(ao ? "occlusion" : "sky-view factor");
      HorizonOutputs outputs;
      (ao ? outputs.ambient_occlusion : outputs.sky_view_factor) = true;
      const auto plane = [&](const HorizonResult& r) { return ao ? r.ambient_occlusion : r.sky_view_factor; };
      HorizonOptions options;
      options.directions = 1024;
      const std::vector<float> truth = plane(computeHorizons(testContext(), field, options, outputs));
      outputs.error_estimate = true;
      double last = 1.0;
      for (int K : {16, 32, 64, 128, 256}) {
        SCOPED_TRACE(K);
        options.directions = K;
        const HorizonResult r = computeHorizons(testContext(), field, options, outputs);
        EXPECT_LT(r.estimated_error, last);
        EXPECT_GE(r.estimated_error, p99Difference(plane(r), truth));
        last = r.estimated_error;
      }
    }
  }
}

// The estimate of a maximum error's run is the raw one (half the halves' difference) divided by
// 2^p - 1, p the order its fall measures (raw ~ K^-p) between the run and the latest earlier one
// of at most half its K, within 1 .. kMaxRichardsonOrder: a single run keeps the raw estimate, a
// steeper fall divides by more, and the divisor never shrinks as p grows.
TEST(HorizonMaxError, TheEstimateIsTheRawOneOverTheRichardsonDivisor) {
  using detail::EstimateRun;
  EXPECT_EQ(detail::estimateOrder({{16, 0.1}}), 1.0);
  EXPECT_EQ(detail::richardsonDivisor(1.0), 1.0);
  EXPECT_NEAR(detail::richardsonDivisor(1.1), std::pow(2.0, 1.1) - 1.0, 1e-12);
  // K^-1.05 from 32 to 128: measured; from 96 to 128 too near (the latest at most half 128 is 32).
  const double raw32 = 0.05, raw128 = raw32 * std::pow(4.0, -1.05);
  EXPECT_NEAR(detail::estimateOrder({{32, raw32}, {128, raw128}}), 1.05, 1e-9);
  EXPECT_NEAR(detail::estimateOrder({{16, 1.0}, {32, raw32}, {96, raw128 * 2}, {128, raw128}}), 1.05, 1e-9);
  EXPECT_EQ(detail::estimateOrder({{96, raw32}, {128, raw128}}), 1.0);
  // Clamped: slower than K^-1 (or rising) counts as 1, faster than K^-1.1 as 1.1.
  EXPECT_EQ(detail::estimateOrder({{32, 0.05}, {128, 0.04}}), 1.0);
  EXPECT_EQ(detail::estimateOrder({{32, 0.05}, {128, 0.06}}), 1.0);
  EXPECT_EQ(detail::estimateOrder({{32, 0.05}, {128, 0.0001}}), detail::kMaxRichardsonOrder);
  double last = 0.0;
  for (double order = 1.0; order <= detail::kMaxRichardsonOrder; order += 0.02) {
    EXPECT_GE(detail::richardsonDivisor(order), last);
    last = detail::richardsonDivisor(order);
  }
  // A whole-field run: its estimate is the raw estimate of a fixed run at its last K over the
  // divisor its runs measure, pixel by pixel.
  const HeightField field = makeSyntheticField("city", 48, 40);
  HorizonOptions options;
  options.max_error = 0.01;
  HorizonOutputs svf;
  svf.sky_view_factor = true;
  const HorizonResult chosen = computeHorizons(testContext(), field, options, svf);
  ASSERT_GE(chosen.runs.size(), 2u) << "one run: nothing measured";
  std::vector<EstimateRun> runs;
  HorizonResult fixed;
  HorizonOutputs raw = svf;
  raw.error_estimate = true;
  for (int K : chosen.runs) {
    HorizonOptions at = options;
    at.max_error = 0.0;
    at.directions = K;
    fixed = computeHorizons(testContext(), field, at, raw);
    runs.push_back({K, fixed.estimated_error});
  }
  const double divisor = detail::richardsonDivisor(detail::estimateOrder(runs));
  EXPECT_GT(divisor, 1.0) << "the city's estimate falls faster than K^-1 here";
  for (std::size_t p = 0; p < field.pixelCount(); ++p)
    ASSERT_NEAR(chosen.error_estimate[p], fixed.error_estimate[p] / divisor, 1e-6 * fixed.error_estimate[p]) << p;
  EXPECT_NEAR(chosen.estimated_error, fixed.estimated_error / divisor, 1e-6 * fixed.estimated_error);
  // One tile: the least and the most divisor are that one.
  EXPECT_DOUBLE_EQ(chosen.richardson_divisor_least, divisor);
  EXPECT_DOUBLE_EQ(chosen.richardson_divisor_most, divisor);
}

// The next K: more than the last, a multiple of 8; the K predicted to meet E never fewer for a
// smaller error or a larger estimate; a far prediction takes a probe (twice the last K, or a sixth
// of the way) below it, a near one is run at once. (The probe itself is not monotone: just past
// four times the last K it drops to twice it.)
TEST(HorizonMaxError, TheNextKGrowsAsTheErrorShrinks) {
  using detail::EstimateRun;
  for (const std::vector<EstimateRun>& before :
       {std::vector<EstimateRun>{{16, 0.2}}, std::vector<EstimateRun>{{16, 0.2}, {32, 0.09}},
        std::vector<EstimateRun>{{16, 0.2}, {64, 0.03}, {128, 0.02}}}) {
    int last_predicted = 0;
    for (double E : {0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001, 1e-4}) {
      SCOPED_TRACE(std::to_string(before.size()) + " runs, E " + std::to_string(E));
      const detail::NextErrorRun next = detail::nextDirectionsForError(before, E);
      EXPECT_GT(next.directions, before.back().directions);
      EXPECT_EQ(next.directions % 8, 0);
      EXPECT_GE(next.predicted, last_predicted);
      EXPECT_LE(next.directions, kMaxAutoDirections);
      last_predicted = next.predicted;
    }
    std::vector<EstimateRun> larger = before;
    larger.back().raw *= 1.5;
    EXPECT_GE(detail::nextDirectionsForError(larger, 0.01).predicted,
              detail::nextDirectionsForError(before, 0.01).predicted);
  }
  // K^-1.5 from 32 to 128: 0.0125 needs 128 (raw / divisor / (0.9 x 0.0125))^(1/1.5), within 4
  // times 128: run at once; 0.002 about 6 times 128: first a probe at twice 128.
  const double raw = 0.03;
  const std::vector<EstimateRun> runs{{32, raw * 8.0}, {128, raw}};
  const double divisor = detail::richardsonDivisor(detail::kMaxRichardsonOrder);
  const double near = 128 * std::pow(raw / divisor / (detail::kErrorAim * 0.0125), 1.0 / 1.5);
  ASSERT_LT(near, 4 * 128);
  EXPECT_EQ(detail::nextDirectionsForError(runs, 0.0125).directions, static_cast<int>(std::ceil(near / 8) * 8));
  const detail::NextErrorRun far = detail::nextDirectionsForError(runs, 0.002);
  EXPECT_EQ(far.directions, 256);
  EXPECT_GT(far.predicted, 256);
}

TEST(HorizonMaxError, BadRequestsAreRefused) {
  const HeightField field = makeSyntheticField("noise", 16, 16);
  HorizonOutputs svf;
  svf.sky_view_factor = true;
  HorizonOptions options;
  for (double E :
       {-0.01, 1.0, 2.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    options.max_error = E;
    EXPECT_THROW(computeHorizons(testContext(), field, options, svf), InvalidArgument) << E;
  }
  options.max_error = 0.01;
  HorizonOutputs angles = svf;
  angles.horizon_angles = true;
  EXPECT_THROW(computeHorizons(testContext(), field, options, angles), InvalidArgument);
  // Beyond kMaxAutoDirections by a run's prediction (after the first run, when even the fastest fall
  // it assumes, K^-2, needs more).
  options.max_error = 1e-7;
  try {
    computeHorizons(testContext(), field, options, svf);
    ADD_FAILURE() << "an error of 1e-7 was accepted";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("directions"), std::string::npos) << error.what();
  }
  options.max_error = 0.0;
  options.directions = 1;
  HorizonOutputs one = svf;
  one.error_estimate = true;
  EXPECT_THROW(computeHorizons(testContext(), field, options, one), InvalidArgument);
  // A tile without an error to refine toward would be ignored: refused.
  HorizonOptions tiled;
  tiled.error_tile = kMinErrorTile;
  EXPECT_THROW(computeHorizons(testContext(), field, tiled, svf), InvalidArgument);
  // A tile of fewer pixels stops on a few pixels' estimates, low by chance: refused.
  tiled.max_error = 0.02;
  for (const int tile : {1, 8, kMinErrorTile - 1}) {
    tiled.error_tile = tile;
    EXPECT_THROW(computeHorizons(testContext(), field, tiled, svf), InvalidArgument) << tile;
  }
  // A tile past the field is the whole field, up to INT_MAX (whose tile sums overflowed int: a
  // crash).
  tiled.error_tile = std::max(field.width, field.height);
  const HorizonResult whole = computeHorizons(testContext(), field, tiled, svf);
  for (const int tile : {INT_MAX - 30, INT_MAX}) {
    tiled.error_tile = tile;
    const HorizonResult past = computeHorizons(testContext(), field, tiled, svf);
    EXPECT_EQ(past.sky_view_factor, whole.sky_view_factor) << tile;
    EXPECT_EQ(past.pixel_directions, whole.pixel_directions) << tile;
  }
}

}  // namespace
}  // namespace hfvis
