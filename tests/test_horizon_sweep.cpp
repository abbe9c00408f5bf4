// test_horizon_sweep.cpp: the hull-stack sweep and the naive march against their oracles:
// exactness on identical line samples, the lattice geometry, kernels against the scalar
// references in both buffer layouts, and the sweep against the naive march where both
// sample the same points.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <cstring>

#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/sun_shading.hpp"
#include "hfvis_testing/horizon_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "core/horizon_common.hpp"
#include "reference_internal.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::awkwardSizes;
using testing::nearlyEqual;
using testing::testContext;

HorizonOutputs allOutputs() {
  HorizonOutputs o;
  o.horizon_angles = o.horizon_distances = o.sky_view_factor = o.ambient_occlusion = true;
  return o;
}

// Exactness on a line: on the very samples of every lattice line (as the reference takes
// them, and the kernel takes the same, see below), the occluder the stack reports casts the
// same elevation as the steepest of all farther samples (brute force, double precision).
TEST(HorizonSweepLine, StackEqualsBruteForceMaximumOnEveryHardCase) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      const HeightField field = makeSyntheticField(name, w, h, 7);
      const auto prepared = detail::prepareHeights(field);
      HorizonOptions options;
      options.directions = 9;
      options.azimuth_offset = 0.3;
      for (double spu : {1.0, 3.0}) {
        options.samples_per_unit = spu;
        int checked = 0;
        for (const auto& d : detail::latticeDirections(field, options, true, options.azimuth_tolerance)) {
          SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " step (" +
                       std::to_string(d.a) + ", " + std::to_string(d.b) + ") spu " + std::to_string(spu));
          for (const auto& line : detail::latticeLines(d, w, h)) {
            const auto samples = detail::latticeLineSamples(field, prepared.heights, d, spu, line);
            for (std::size_t q = 0; q < samples.size(); ++q) {
              const auto& s = samples[q];
              // (A peak inside a segment is pushed only where it is on the hull, and its own
              // occluder is not asked for; as an earlier sample it counts like any other, but
              // within its height's rounding: the sweep decides a peak by its slope from the
              // sample after it, -(B/2 + C)/span, while its height, a float near the sample's,
              // seen over a fraction of a pixel, gives that slope only to ulp(h) / distance, and
              // its position to ulp(position) times rise / distance^2.)
              if (std::isnan(s.height) || s.peak) continue;
              double lowest = -M_PI, highest = -M_PI;  // steepest farther sample, within rounding
              double peak_rounding = 0.0;  // the largest, for an occluder that is a peak
              for (std::size_t k = 0; k < q; ++k) {
                if (std::isnan(samples[k].height)) continue;
                ASSERT_LT(samples[k].position, s.position) << "positions must increase along the sweep";
                const double run = double(s.position) - samples[k].position;
                const double rise = double(samples[k].height) - s.height;
                const double slope = std::atan2(rise, run);
                const double rounding =
                    samples[k].peak ? 4.0 * FLT_EPSILON *
                                          ((std::fabs(samples[k].height) + std::fabs(s.height)) / run +
                                           std::fabs(s.position) * std::fabs(rise) / (run * run))
                                    : 0.0;
                lowest = std::max(lowest, slope - rounding);
                highest = std::max(highest, slope + rounding);
                peak_rounding = std::max(peak_rounding, rounding);
              }
              if (highest == -M_PI) {
                ASSERT_EQ(s.occluder, -1) << "sample " << q << " has no farther sample";
                continue;
              }
              ASSERT_GE(s.occluder, 0) << "sample " << q;
              ASSERT_GT(s.occluder_run, 0.0f);
              const double reported = std::atan2(double(s.occluder_rise), double(s.occluder_run));
              ASSERT_GE(reported, lowest - peak_rounding - 1e-6) << "sample " << q;
              ASSERT_LE(reported, highest + 1e-6) << "sample " << q;
              ++checked;
            }
          }
        }
        if (w > 1 && h > 1 && name != "nan_holes") {
          EXPECT_GT(checked, 0);
        }
      }
    }
  }
}

// The same within a maximum distance (a window of W pixels along the line): every receiver's
// occluder casts the elevation of the steepest farther sample at most W away, or there is
// none, on every hard case, for windows shorter than a period, a few periods and longer.
TEST(HorizonSweepLine, WindowedStackEqualsBruteForceWithinTheWindow) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      const HeightField field = makeSyntheticField(name, w, h, 7);
      const auto prepared = detail::prepareHeights(field);
      HorizonOptions options;
      options.directions = 9;
      options.azimuth_offset = 0.3;
      for (double spu : {1.0, 3.0}) {
        for (float window : {0.6f, 2.37f, 7.9f}) {
          const detail::LatticeWindow cut{window, 1.0f / window};
          int checked = 0;
          for (const auto& d : detail::latticeDirections(field, options, true, options.azimuth_tolerance)) {
            SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " step (" +
                         std::to_string(d.a) + ", " + std::to_string(d.b) + ") spu " + std::to_string(spu) +
                         " window " + std::to_string(window));
            for (const auto& line : detail::latticeLines(d, w, h)) {
              const auto samples = detail::latticeLineSamples(field, prepared.heights, d, spu, line, 0.0f, cut);
              for (std::size_t q = 0; q < samples.size(); ++q) {
                const auto& s = samples[q];
                if (std::isnan(s.height) || s.receiver < 0) continue;
                double brute = -M_PI;  // steepest farther sample within the window
                for (std::size_t k = 0; k < q; ++k) {
                  // A peak inside a segment counts where it lies within the window, though its
                  // segment's far end (the sample before it) may not (it had counted only once
                  // that end was within: a peak at 3.5 pixels dropped within 4.1).
                  if (std::isnan(samples[k].height) || s.position - samples[k].position > window) continue;
                  brute = std::max(brute, std::atan2(double(samples[k].height) - s.height,
                                                     double(s.position) - samples[k].position));
                }
                if (brute == -M_PI) {
                  ASSERT_EQ(s.occluder_run, 0.0f) << "receiver " << q << " has no sample within the window";
                  continue;
                }
                ASSERT_GT(s.occluder_run, 0.0f) << "receiver " << q;
                ASSERT_LE(s.occluder_run, window) << "receiver " << q;
                ASSERT_NEAR(std::atan2(double(s.occluder_rise), double(s.occluder_run)), brute, 1e-6)
                    << "receiver " << q;
                ++checked;
              }
            }
          }
          if (w > 1 && h > 1 && name != "nan_holes" && window > 1.0f) {  // a shorter one may hold none
            EXPECT_GT(checked, 0);
          }
        }
      }
    }
  }
}

// Every receiver sits on the line through its own centre: each pixel is exactly one
// receiver of one line per direction, and the sample table puts exact grid crossings on
// grid lines.
TEST(HorizonSweepLine, EveryPixelIsOneReceiverAndCrossingsLieOnGridLines) {
  for (auto [w, h] : awkwardSizes()) {  // steps longer than the field included
    HeightField field = makeSyntheticField("noise", w, h, 1);
    HorizonOptions options;
    options.directions = 64;
    for (bool exact : {true, false}) {
      for (const auto& d : detail::latticeDirections(field, options, exact, options.azimuth_tolerance)) {
        SCOPED_TRACE("step (" + std::to_string(d.a) + ", " + std::to_string(d.b) + ")");
        std::vector<int> seen(field.pixelCount(), 0);
        for (const auto& line : detail::latticeLines(d, field.width, field.height)) {
          for (int i = 0; i < line.receivers; ++i) {
            const int c = line.col - i * d.a, r = line.row - i * d.b;
            ASSERT_TRUE(c >= 0 && c < field.width && r >= 0 && r < field.height);
            ++seen[r * field.width + c];
          }
          const int c = line.col + d.a, r = line.row + d.b;  // the next step leaves the field
          EXPECT_FALSE(c >= 0 && c < field.width && r >= 0 && r < field.height);
        }
        for (int n : seen) ASSERT_EQ(n, 1);
        const auto samples = detail::latticeSamples(d, 1.0);
        ASSERT_EQ(samples.back().tau, 0.0f);
        std::size_t on_grid_lines = 0;
        for (const auto& s : samples) on_grid_lines += s.ex == 0 || s.ey == 0;
        if (d.a != 0 && d.b != 0) {  // |a| + |b| - 1 crossings; denser sampling adds points between
          EXPECT_EQ(on_grid_lines, std::size_t(std::abs(d.a) + std::abs(d.b) - 1));
          EXPECT_EQ(samples.size(), on_grid_lines);
          EXPECT_GT(detail::latticeSamples(d, 4.0).size(), samples.size());
        } else {  // along a grid line the surface is linear: the pixel centre alone
          EXPECT_EQ(samples.size(), 1u);
          EXPECT_EQ(detail::latticeSamples(d, 4.0).size(), 1u);
        }
      }
    }
  }
}

// Direction choice: planes get steps within the tolerance of phi_k; quadrature directions
// honour the azimuth offset, carry weights summing to 1, and where K outruns the lattice
// (near the axes no step lies within atan(1/64)) equal steps are merged into one.
TEST(HorizonSweepLine, DirectionsHonourTheToleranceAndQuadratureWeightsSumToOne) {
  HeightField field = makeSyntheticField("flat", 50, 40);
  for (double cell_y : {1.0, 1.24}) {
    field.cell_size_y = cell_y;
    for (int K : {1, 2, 3, 7, 64, 1024}) {
      HorizonOptions options;
      options.directions = K;
      options.azimuth_offset = 0.3;
      SCOPED_TRACE("K " + std::to_string(K) + " cell_y " + std::to_string(cell_y));
      const auto exact = detail::latticeDirections(field, options, true, options.azimuth_tolerance);
      // Within the tolerance wherever a step is; the lattice's widest gap (between an axis and
      // (64, 1), 0.9 deg, stretched by the cells' aspect) bounds the fallback to the closest.
      const double fallback = 0.6 * M_PI / 180.0;
      for (int k = 0; k < std::min(K, 64); ++k)
        EXPECT_NEAR(exact[k].azimuth, directionAzimuth(k, options), fallback);
      if (cell_y == 1.0 && K <= 64) {
        HorizonOptions plain = options;
        plain.azimuth_offset = 0.0;
        const auto at_phi = detail::latticeDirections(field, plain, true, plain.azimuth_tolerance);
        for (int k = 0; k < K; ++k)
          EXPECT_NEAR(at_phi[k].azimuth, directionAzimuth(k, plain), plain.azimuth_tolerance);
      }
      const auto quadrature = detail::latticeDirections(field, options, false, options.azimuth_tolerance);
      double sum = 0.0;
      int runs = 0;
      for (int k = 0; k < K; ++k) {
        EXPECT_GE(quadrature[k].weight, 0.0);
        sum += quadrature[k].weight;
        runs += quadrature[k].weight > 0.0;
        for (int m = 0; m < k; ++m) {
          if (quadrature[m].a == quadrature[k].a && quadrature[m].b == quadrature[k].b) {
            EXPECT_TRUE(quadrature[m].weight == 0.0 || quadrature[k].weight == 0.0);
          }
        }
        if (K <= 64) {
          EXPECT_LT(std::abs(quadrature[k].azimuth - directionAzimuth(k, options)), M_PI / K);
        }
      }
      EXPECT_NEAR(sum, 1.0, 1e-12);
      if (K == 1024) {
        EXPECT_LT(runs, K);
      }
    }
  }
}

// Kernel results equal the scalar reference of the same algorithm, for both methods, in
// both buffer layouts (with row_spacing, on testing::setRowSpacing's grid).
// With `cut`, each field is one cut out of a larger one (HeightField::origin: its positions along
// the larger field's lines, the larger field's lowest height 2 below its own; with row_spacing
// the larger field's rows setRowSpacing's over its rows, the field's rows 5 .. 5 + h of them).
void expectKernelMatchesReference(HorizonMethod method, double samples_per_unit, double curvature = 0.0,
                                  double max_distance = 0.0, bool row_spacing = false, bool cut = false) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : awkwardSizes()) {
        SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h));
        HeightField field = makeSyntheticField(name, w, h, 3);
        field.cell_size_x = 1.5;
        if (row_spacing) testing::setRowSpacing(field);
        if (cut) {
          float lowest = INFINITY;
          for (float v : field.heights) lowest = std::isfinite(v) ? std::min(lowest, v) : lowest;
          field.origin = {11, 5, w + 17, h + 9, double(lowest) - 2.0};
          if (row_spacing) {
            HeightField larger = makeSyntheticField("flat", 1, h + 9);
            testing::setRowSpacing(larger);
            field.origin.row_cell_size_x = larger.row_cell_size_x;
            field.origin.row_cell_size_y = larger.row_cell_size_y;
            field.row_cell_size_x.assign(larger.row_cell_size_x.begin() + 5,
                                         larger.row_cell_size_x.begin() + 5 + h);
            field.row_cell_size_y.assign(larger.row_cell_size_y.begin() + 5,
                                         larger.row_cell_size_y.begin() + 5 + h);
          }
        }
        HorizonOptions options;
        options.directions = 7;
        options.azimuth_offset = 0.1;
        options.method = method;
        options.samples_per_unit = samples_per_unit;
        options.curvature = curvature;
        options.max_distance = max_distance;
        for (bool planes : {true, false}) {  // exact azimuths, or quadrature directions
          HorizonOutputs outputs;
          outputs.horizon_angles = outputs.horizon_distances = planes;
          outputs.sky_view_factor = outputs.ambient_occlusion = true;
          const auto device = computeHorizons(context, field, options, outputs);
          const auto reference = referenceHorizons(field, options, outputs);
          const float tolerance = testing::divisionTolerance();
          EXPECT_EQ(device.azimuths, reference.azimuths);
          EXPECT_TRUE(nearlyEqual(device.angles, reference.angles, tolerance));
          EXPECT_TRUE(nearlyEqual(device.distances, reference.distances, tolerance * float(w + h)));
          EXPECT_TRUE(nearlyEqual(device.sky_view_factor, reference.sky_view_factor, tolerance));
          EXPECT_TRUE(nearlyEqual(device.ambient_occlusion, reference.ambient_occlusion, tolerance));
        }
      }
    }
  });
}

TEST(HorizonKernels, SweepMatchesScalarReference) { expectKernelMatchesReference(HorizonMethod::Sweep, 1.0); }

TEST(HorizonKernels, SweepMatchesScalarReferenceWithDenserSampling) {
  expectKernelMatchesReference(HorizonMethod::Sweep, 2.5);
}

TEST(HorizonKernels, NaiveMatchesScalarReference) { expectKernelMatchesReference(HorizonMethod::Naive, 1.0); }

// Earth curvature, with a coefficient large enough to matter on these small fields (a drop of
// several height units across them).
TEST(HorizonKernels, SweepMatchesScalarReferenceWithCurvature) {
  expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.004);
}

TEST(HorizonKernels, NaiveMatchesScalarReferenceWithCurvature) {
  expectKernelMatchesReference(HorizonMethod::Naive, 1.0, 0.004);
}

// Within a maximum distance (ground units; the cells are 1.5 x 1): shorter than a pixel, a
// few pixels, about the fields' size.
TEST(HorizonKernels, SweepMatchesScalarReferenceWithinAMaximumDistance) {
  for (double d : {1.2, 4.3, 29.0}) {
    SCOPED_TRACE("max distance " + std::to_string(d));
    expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.0, d);
  }
}

TEST(HorizonKernels, SweepMatchesScalarReferenceWithinAMaximumDistanceDenserAndCurved) {
  expectKernelMatchesReference(HorizonMethod::Sweep, 2.5, 0.004, 6.1);
}

// A field cut out of a larger one, its positions along the larger field's lines: whole, within
// maximum distances, denser and curved.
TEST(HorizonKernels, SweepMatchesScalarReferenceOnAFieldCutFromALargerOne) {
  expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.0, 0.0, false, true);
  for (double d : {1.2, 4.3, 29.0}) {
    SCOPED_TRACE("max distance " + std::to_string(d));
    expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.0, d, false, true);
  }
  expectKernelMatchesReference(HorizonMethod::Sweep, 2.5, 0.004, 6.1, false, true);
}

TEST(HorizonKernels, NaiveMatchesScalarReferenceWithinAMaximumDistance) {
  expectKernelMatchesReference(HorizonMethod::Naive, 1.0, 0.0, 4.3);
}

// Per-row spacing (latitude / longitude grids), with denser sampling and curvature too.
TEST(HorizonKernels, SweepMatchesScalarReferenceWithPerRowSpacing) {
  expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.0, 0.0, true);
  expectKernelMatchesReference(HorizonMethod::Sweep, 2.5, 0.004, 0.0, true);
}

// And within maximum distances (ground units: positions are ground lengths there), denser and
// curved too.
TEST(HorizonKernels, SweepMatchesScalarReferenceWithPerRowSpacingWithinAMaximumDistance) {
  for (double d : {1.2, 4.3, 29.0}) {
    SCOPED_TRACE("max distance " + std::to_string(d));
    expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.0, d, true);
  }
  expectKernelMatchesReference(HorizonMethod::Sweep, 2.5, 0.004, 6.1, true);
}

// Per-row spacing on a field cut from a larger one: each line starts at its position along the
// larger field's line (lineStartPosition), plain, within maximum distances, denser and curved.
TEST(HorizonKernels, SweepMatchesScalarReferenceWithPerRowSpacingOnAFieldCutFromALargerOne) {
  expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.0, 0.0, true, true);
  for (double d : {1.2, 4.3, 29.0}) {
    SCOPED_TRACE("max distance " + std::to_string(d));
    expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 0.0, d, true, true);
  }
  expectKernelMatchesReference(HorizonMethod::Sweep, 2.5, 0.004, 6.1, true, true);
}

TEST(HorizonKernels, NaiveMatchesScalarReferenceWithPerRowSpacing) {
  expectKernelMatchesReference(HorizonMethod::Naive, 1.0, 0.004, 0.0, true);
  expectKernelMatchesReference(HorizonMethod::Naive, 1.0, 0.004, 4.3, true);
}

// On the axes with per-row spacing both sum the same ground lengths: along a row its spacing,
// along a column the spacing at the half rows between pixel centres; also within maximum
// distances.
TEST(HorizonKernels, SweepEqualsNaiveOnAxisDirectionsWithPerRowSpacing) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : awkwardSizes()) {
        for (double max_distance : {0.0, 2.2, 7.7}) {  // both cut at the ground length summed
          SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " max distance " +
                       std::to_string(max_distance));
          HeightField field = makeSyntheticField(name, w, h, 5);
          testing::setRowSpacing(field);
          HorizonOptions options;
          options.directions = 4;
          options.max_distance = max_distance;
          HorizonOutputs outputs;
          outputs.horizon_angles = true;
          const auto sweep = computeHorizons(context, field, options, outputs);
          options.method = HorizonMethod::Naive;
          const auto naive = computeHorizons(context, field, options, outputs);
          EXPECT_TRUE(nearlyEqual(sweep.angles, naive.angles, 1e-5f));
        }
      }
    }
  });
}

// On the four axis directions the naive march samples the pixel centres of the receiver's
// own row or column, which are the sweep's samples, and the sweep's limit at the receiver
// is the slope to the first pixel. So both give the same horizons.
TEST(HorizonKernels, SweepEqualsNaiveOnAxisDirections) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h));
      const HeightField field = makeSyntheticField(name, w, h, 5);
      HorizonOptions options;
      options.directions = 4;
      HorizonOutputs outputs;
      outputs.horizon_angles = true;
      const auto sweep = computeHorizons(testContext(), field, options, outputs);
      options.method = HorizonMethod::Naive;
      const auto naive = computeHorizons(testContext(), field, options, outputs);
      EXPECT_TRUE(nearlyEqual(sweep.angles, naive.angles, 1e-5f));
    }
  }
}

// The same within a maximum distance: both count the pixel centres at most D away (D a whole
// number of pixels, so both cut at the same samples), in both layouts.
TEST(HorizonKernels, SweepEqualsNaiveOnAxisDirectionsWithinAMaximumDistance) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : awkwardSizes()) {
        for (double d : {1.0, 3.0, 10.0}) {
          SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " max distance " +
                       std::to_string(d));
          const HeightField field = makeSyntheticField(name, w, h, 5);
          HorizonOptions options;
          options.directions = 4;
          options.max_distance = d;
          HorizonOutputs outputs;
          outputs.horizon_angles = outputs.horizon_distances = true;
          const auto sweep = computeHorizons(context, field, options, outputs);
          options.method = HorizonMethod::Naive;
          const auto naive = computeHorizons(context, field, options, outputs);
          EXPECT_TRUE(nearlyEqual(sweep.angles, naive.angles, 1e-5f));
          for (float distance : sweep.distances) {
if (!std::isnan(distance)) {
  ASSERT_LE(distance, d);
}
          }
        }
      }
    }
  });
}

TEST(HorizonKernels, BatchingUnderATinyMemoryBudgetChangesNothing) {
  const HeightField field = makeSyntheticField("noise", 40, 41, 9);
  testing::forEachLayout([&](const ComputeContext& context) {
    HorizonOptions options;
    options.directions = 9;
    const auto outputs = allOutputs();
    const auto whole = computeHorizons(context, field, options, outputs);
    int batches = 0;
    options.memory_budget_bytes = 100 * 1024;  // two directions per batch, stacks in chunks of lines
    options.progress = [&](int, int) { ++batches; };
    const auto batched = computeHorizons(context, field, options, outputs);
    EXPECT_GT(batches, 2);
    EXPECT_TRUE(nearlyEqual(batched.angles, whole.angles, 0.0f));
    EXPECT_TRUE(nearlyEqual(batched.distances, whole.distances, 0.0f));
    EXPECT_TRUE(nearlyEqual(batched.sky_view_factor, whole.sky_view_factor, 0.0f));
    EXPECT_TRUE(nearlyEqual(batched.ambient_occlusion, whole.ambient_occlusion, 0.0f));
    options.memory_budget_bytes = 1024;
    EXPECT_THROW(computeHorizons(context, field, options, outputs), MemoryBudgetError);
  });
}

// Bit for bit: the same float in every place (NaN where the other has NaN).
::testing::AssertionResult bitsEqual(const std::vector<float>& actual, const std::vector<float>& expected) {
  if (actual.size() != expected.size())
    return ::testing::AssertionFailure() << "sizes differ: " << actual.size() << " vs " << expected.size();
  for (std::size_t i = 0; i < actual.size(); ++i) {
    const float a = actual[i], e = expected[i];
    if (std::isnan(a) ? !std::isnan(e) : std::memcmp(&a, &e, sizeof(float)) != 0)
      return ::testing::AssertionFailure() << "[" << i << "] " << a << " vs " << e;
  }
  return ::testing::AssertionSuccess();
}

void expectBitsEqual(const HorizonResult& strips, const HorizonResult& whole) {
  EXPECT_TRUE(bitsEqual(strips.angles, whole.angles));
  EXPECT_TRUE(bitsEqual(strips.distances, whole.distances));
  EXPECT_TRUE(bitsEqual(strips.sky_view_factor, whole.sky_view_factor));
  EXPECT_TRUE(bitsEqual(strips.ambient_occlusion, whole.ambient_occlusion));
}

// A field in strips of rows, each line's hull stack carried from strip to strip, gives the
// whole-field result bit for bit: every hard case on three awkward sizes, strips of 1 and 6 rows,
// steps up to 5 rows (K = 24 exact azimuths), curvature, denser sampling and per-row spacing, in
// both layouts.
TEST(HorizonKernels, StripsEqualTheWholeFieldBitForBit) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : {std::pair{1, 9}, std::pair{7, 13}, std::pair{33, 20}}) {
        const HeightField field = makeSyntheticField(name, w, h, 3);
        HorizonOptions options;
        options.directions = 24;
        const auto whole = computeHorizons(context, field, options, allOutputs());
        for (int rows : {1, 6}) {
          if (rows >= h) continue;
          SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + ", strips of " +
                       std::to_string(rows) + " rows");
          options.strip_rows = rows;
          int strips = 0;
          const int strips_per_run = (h + rows - 1) / rows;  // (C++17 lambdas take no structured binding)
          options.strip_progress = [&](int done, int all) {
            EXPECT_EQ(all, strips_per_run);
            strips += done == all;
          };
          expectBitsEqual(computeHorizons(context, field, options, allOutputs()), whole);
          EXPECT_EQ(strips, options.directions);
          options.strip_progress = nullptr;
          options.strip_rows = 0;
        }
      }
    }
    // Curvature, denser sampling, per-row spacing; quadrature directions (svf and ao alone).
    HeightField field = makeSyntheticField("sine", 37, 45, 1);
    for (int variant = 0; variant < 3; ++variant) {
      SCOPED_TRACE("variant " + std::to_string(variant));
      HorizonOptions options;
      options.directions = 32;
      if (variant == 0) options.curvature = 0.01;
      if (variant == 1) options.samples_per_unit = 3.0;
      if (variant == 2) testing::setRowSpacing(field);
      for (const HorizonOutputs& outputs : {allOutputs(), HorizonOutputs{false, false, true, true}}) {
        const auto whole = computeHorizons(context, field, options, outputs);
        options.strip_rows = 4;
        expectBitsEqual(computeHorizons(context, field, options, outputs), whole);
        options.strip_rows = 0;
      }
    }
  });
}

// The same within maximum distances: the window's blocks resumed part-way, strips that start
// inside a block (whose pass reaches back into the halo), a window of 40 pixels across many
// strips, with curvature too, in both layouts; and on rows of their own spacing, where
// positions are ground lengths (the receivers' of earlier strips kept on the host).
TEST(HorizonKernels, StripsWithinAMaximumDistanceEqualTheWholeFieldBitForBit) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const char* name : {"noise", "nan_holes", "spikes"}) {
      for (double max_distance : {2.5, 9.0, 40.0}) {
       for (bool row_spacing : {false, true}) {  // positions ground lengths summed row by row
        SCOPED_TRACE(std::string(name) + " max distance " + std::to_string(max_distance) +
                     (row_spacing ? ", rows of their own spacing" : ""));
        HeightField field = makeSyntheticField(name, 33, 31, 2);
        if (row_spacing) testing::setRowSpacing(field);
        HorizonOptions options;
        options.directions = 24;
        options.max_distance = max_distance;
        options.curvature = max_distance == 9.0 ? 0.01 : 0.0;
        const auto whole = computeHorizons(context, field, options, allOutputs());
        for (int rows : {1, 5}) {
          SCOPED_TRACE("strips of " + std::to_string(rows) + " rows");
          options.strip_rows = rows;
          expectBitsEqual(computeHorizons(context, field, options, allOutputs()), whole);
        }
       }
      }
    }
    // A tall field at K = 8 (steps of at most one row): halos of a few rows, so strips read
    // positions and heights of earlier strips from the halo alone.
    for (bool row_spacing : {false, true}) {
      HeightField field = makeSyntheticField("noise", 17, 90, 5);
      if (row_spacing) testing::setRowSpacing(field);
      HorizonOptions options;
      options.directions = 8;
      options.max_distance = 3.5;
      const auto whole = computeHorizons(context, field, options, allOutputs());
      for (int rows : {1, 4}) {
        SCOPED_TRACE("tall field, strips of " + std::to_string(rows) + " rows" + (row_spacing ? ", own spacing" : ""));
        options.strip_rows = rows;
        expectBitsEqual(computeHorizons(context, field, options, allOutputs()), whole);
      }
    }
  });
}

// A field cut out of a larger one with its origin given (HeightField::origin, as the Python
// package's Dask path cuts each chunk with its halo) equals the larger field bit for bit on the
// cut's pixels farther than ceil(max_distance / smallest cell) + 2 pixels from its edges inside
// the larger field (those at the larger field's own edges are edges in both): hard cases with
// nodata, cuts smaller than that margin, at the larger field's edges and in its middle, exact
// azimuths and quadrature directions, curvature, denser sampling, strips, sun shading, per-row
// spacing (variants 4 to 6: a latitude / longitude grid, positions whole units of ground length
// along the larger field's lines); both layouts.
TEST(HorizonKernels, AFieldCutFromALargerOneEqualsItBitForBitInside) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const char* name : {"nan_holes", "city", "spikes", "noise"}) {
      HeightField whole = makeSyntheticField(name, 61, 53, 4);
      whole.cell_size_x = 1.5;
      for (int variant = 0; variant < 7; ++variant) {
        const bool rows = variant >= 4;  // then variants 0 .. 2's options again
        if (variant == 4) testing::setRowSpacing(whole);
        HorizonOptions options;
        options.directions = variant % 4 == 1 ? 24 : 8;
        options.azimuth_offset = 0.3;
        options.max_distance = variant % 4 == 2 ? 9.0 : 4.6;
        options.curvature = variant % 4 == 2 ? 0.01 : 0.0;
        options.samples_per_unit = variant == 3 ? 2.5 : 1.0;
        // Cells 1.5 x 1 (per-row: at least 0.75 x 1).
        const double smallest = rows ? 0.75 : 1.0;
        const int margin = static_cast<int>(std::ceil(options.max_distance / smallest)) + 2;
        for (auto [x0, y0, w, h] : {std::array{0, 0, 30, 27}, std::array{17, 9, 33, 31}, std::array{40, 30, 21, 23},
                                    std::array{5, 20, 9, 13}, std::array{0, 0, 61, 53}}) {
          SCOPED_TRACE(std::string(name) + " variant " + std::to_string(variant) + " cut at " + std::to_string(x0) +
                       "," + std::to_string(y0) + " " + std::to_string(w) + "x" + std::to_string(h));
          HeightField cut = testing::cropField(whole, x0, y0, w, h);
          if (std::all_of(cut.heights.begin(), cut.heights.end(), [](float v) { return std::isnan(v); })) continue;
          cut.origin = {x0, y0, whole.width, whole.height, heightBase(whole)};
          if (rows) {  // the cut's rows of the larger field's spacing (its centre's cell sizes kept)
            cut.origin.row_cell_size_x = whole.row_cell_size_x;
            cut.origin.row_cell_size_y = whole.row_cell_size_y;
            cut.row_cell_size_x.assign(whole.row_cell_size_x.begin() + y0,
                                       whole.row_cell_size_x.begin() + y0 + h);
            cut.row_cell_size_y.assign(whole.row_cell_size_y.begin() + y0,
                                       whole.row_cell_size_y.begin() + y0 + h);
          }
          // `planes` planes of the cut's values against the larger field's on the pixels inside.
          const int cut_x0 = x0, cut_y0 = y0, cut_w = w,
                    cut_h = h;  // (C++17 lambdas take no structured binding)
          auto expectEqualInside = [&](const std::vector<float>& part, const std::vector<float>& full,
                                       int planes) {
            ASSERT_EQ(part.size(), std::size_t(planes) * cut_w * cut_h);
            int compared = 0;
            for (int k = 0; k < planes; ++k) {
              for (int y = 0; y < cut_h; ++y) {
                for (int x = 0; x < cut_w; ++x) {
                  if (!((cut_x0 == 0 || x >= margin) && (cut_y0 == 0 || y >= margin) &&
                        (cut_x0 + cut_w == whole.width || x < cut_w - margin) &&
                        (cut_y0 + cut_h == whole.height || y < cut_h - margin)))
                    continue;
                  ++compared;
                  const float a = part[(std::size_t(k) * cut_h + y) * cut_w + x];
                  const float b =
                      full[(std::size_t(k) * whole.height + cut_y0 + y) * whole.width + cut_x0 + x];
                  ASSERT_TRUE(std::isnan(a) ? std::isnan(b) : std::memcmp(&a, &b, sizeof a) == 0)
                      << "plane " << k << " pixel " << x << "," << y << ": " << a << " vs " << b;
                }
              }
            }
            if (planes > 0 && (cut_w > 2 * margin || cut_x0 == 0)) {
              EXPECT_GT(compared, 0);
            }
          };
          for (int strip_rows : {0, 4}) {  // strips of 4 rows in variant 3
            if (strip_rows && (variant != 3 || strip_rows >= h)) continue;
            options.strip_rows = strip_rows;
            for (const HorizonOutputs& outputs : {allOutputs(), HorizonOutputs{false, false, true, true}}) {
              HorizonOptions whole_options = options;
              whole_options.strip_rows = 0;
              const HorizonResult full = computeHorizons(context, whole, whole_options, outputs);
              const HorizonResult part = computeHorizons(context, cut, options, outputs);
              const int planes = outputs.horizon_angles ? options.directions : 0;
              expectEqualInside(part.angles, full.angles, planes);
              expectEqualInside(part.distances, full.distances, planes);
              expectEqualInside(part.sky_view_factor, full.sky_view_factor, 1);
              expectEqualInside(part.ambient_occlusion, full.ambient_occlusion, 1);
            }
          }
          options.strip_rows = 0;
          if (variant % 4 == 0) {  // the sun's shading: one sweep in its azimuth, then the normals
            SunLight sun;
            sun.position = {200.0, 15.0};
            expectEqualInside(computeSunShading(context, cut, sun, options).direct,
                              computeSunShading(context, whole, sun, options).direct, 1);
          }
        }
      }
    }
  });
}

// A memory budget below the whole field's needs runs it in strips by itself, with the same
// result; stacks too deep for what the budget leaves are a MemoryBudgetError, not a wrong answer.
TEST(HorizonKernels, ABudgetBelowTheWholeFieldRunsItInStrips) {
  const HeightField field = makeSyntheticField("noise", 300, 200, 4);
  HorizonOptions options;
  options.directions = 16;
  HorizonOutputs outputs;
  outputs.sky_view_factor = outputs.ambient_occlusion = true;
  const auto whole = computeHorizons(testContext(), field, options, outputs);
  options.memory_budget_bytes = 600 * 1024;  // the whole field's sums and normals alone take 1.2 MB
  int strips = 0;
  options.strip_progress = [&](int, int all) { strips = all; };
  expectBitsEqual(computeHorizons(testContext(), field, options, outputs), whole);
  EXPECT_GT(strips, 2);
  options.strip_progress = nullptr;
  // A dome keeps most samples of a line on its hull. 52 KB hold strips of two rows (their
  // buffers half the budget) and leave about 28 KB for stacks, 11 KB for each buffer of those
  // carried: far too few, and strips of one row (computeHorizons tries them) do not help enough.
  const HeightField dome = makeSyntheticField("dome", 300, 200, 4);
  options.memory_budget_bytes = 52 * 1024;
  try {
    computeHorizons(testContext(), dome, options, outputs);
    ADD_FAILURE() << "no MemoryBudgetError";
  } catch (const MemoryBudgetError& error) {
    EXPECT_NE(std::string(error.what()).find("hull stack"), std::string::npos) << error.what();
  }
}

// A strip's receivers of a line are those in its rows, and the strips together hold each
// receiver once.
TEST(HorizonSweepLine, StripsHoldEveryReceiverOnce) {
  const HeightField field = makeSyntheticField("flat", 23, 31);
  HorizonOptions options;
  options.directions = 40;
  for (const auto& d : detail::latticeDirections(field, options, true, options.azimuth_tolerance)) {
    for (const auto& line : detail::latticeLines(d, field.width, field.height)) {
      for (int rows : {1, 2, 5, 31}) {
        int next = 0;
        // In the order the line runs through them.
        for (int step = 0; step * rows < field.height; ++step) {
          const int strips = (field.height + rows - 1) / rows;
          const int s = d.b > 0 ? strips - 1 - step : step;
          const auto [first, end] = detail::receiversInRows(line, d.b, s * rows, (s + 1) * rows);
          if (first == end) continue;
          ASSERT_EQ(first, next) << "a=" << d.a << " b=" << d.b;
          for (int i = first; i < end; ++i) {
            const int row = line.row - i * d.b;
            ASSERT_GE(row, s * rows);
            ASSERT_LT(row, (s + 1) * rows);
          }
          next = end;
        }
        ASSERT_EQ(next, line.receivers);
      }
    }
  }
}

// Chunks of lines cover every line once, fit the scratch they are given (a single line may
// exceed it: a direction always runs), and give each line its own stack slots.
TEST(HorizonSweepLine, ChunksOfLinesFitTheScratchAndNeverShareStacks) {
  const HeightField field = makeSyntheticField("flat", 40, 41);
  HorizonOptions options;
  options.directions = 9;
  for (bool line_major : {true, false}) {
    for (const auto& d : detail::latticeDirections(field, options, true, options.azimuth_tolerance)) {
      const std::size_t per_period = detail::latticeSamples(d, 1.0).size();
      for (std::size_t max_entries : {std::size_t(1), std::size_t(500), std::size_t(1) << 30}) {
        auto lines = detail::latticeLines(d, field.width, field.height);
        const auto chunks = detail::chunkLines(lines, per_period, max_entries, line_major);
        std::size_t next = 0;
        for (const auto& chunk : chunks) {
          ASSERT_EQ(chunk.first, next);
          ASSERT_GT(chunk.count, 0u);
          next += chunk.count;
          if (chunk.count > 1) {
            EXPECT_LE(chunk.stack_entries, max_entries);
          }
          EXPECT_EQ(chunk.stride, line_major ? 1u : chunk.count);
          // Every (line, depth) slot of the chunk is a distinct entry below stack_entries.
          std::vector<int> used(chunk.stack_entries, 0);
          for (std::size_t j = chunk.first; j < chunk.first + chunk.count; ++j) {
            for (std::size_t k = 0; k < detail::lineCapacity(lines[j], per_period); ++k) {
              const std::size_t entry = std::size_t(lines[j].stack) + k * chunk.stride;
              ASSERT_LT(entry, chunk.stack_entries);
              ASSERT_EQ(used[entry]++, 0);
            }
          }
        }
        EXPECT_EQ(next, lines.size());
        if (max_entries == 1) {
          EXPECT_EQ(chunks.size(), lines.size());
        }
      }
    }
  }
}

TEST(HorizonKernels, NodataReceiversAreNaNAndNeverPoisonNeighbours) {
  for (const char* name : {"nan_holes", "infinities"}) {
    const HeightField field = makeSyntheticField(name, 33, 20, 2);
    HorizonOptions options;
    options.directions = 8;
    for (auto method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
      options.method = method;
      const auto r = computeHorizons(testContext(), field, options, allOutputs());
      for (std::size_t p = 0; p < field.pixelCount(); ++p) {
        const bool nodata = !std::isfinite(field.heights[p]);
        EXPECT_EQ(std::isnan(r.sky_view_factor[p]), nodata) << name << " pixel " << p;
        EXPECT_EQ(std::isnan(r.ambient_occlusion[p]), nodata) << name << " pixel " << p;
        for (int k = 0; k < options.directions; ++k)
          ASSERT_EQ(std::isnan(r.angles[k * field.pixelCount() + p]), nodata) << name << " pixel " << p;
      }
    }
  }
}

// A cell with a nodata corner has no surface inside (the viewshed's rule, every operation's). The
// naive march had renormalised a partial cell over its valid corners, which the sweep, sampling
// grid-line crossings and the peaks of whole cells, never saw: looking along the diagonal
// through a cell whose far corner is nodata and one other corner 30 high, the march found 77
// degrees (79 at 64 samples a pixel) and the sweep 0 (the hostile probe's find: a city with
// holes lost up to 0.24 in sky-view factor). Along that diagonal every grid point is 0 and no
// whole cell is crossed but through its corners: the horizon is 0 by both, in both layouts;
// across the cell the other way the 30 of its valid corner still rises (a grid point).
TEST(HorizonKernels, ACellWithANodataCornerHasNoSurfaceInside) {
  const int n = 9, c = 4;  // the receiver (4, 4)
  for (int d = 1; d <= 3; ++d) {
    HeightField field = testing::fieldFrom(n, n, std::vector<float>(n * n, 0.0f));
    field.heights[(c - d) * n + (c - d)] = std::numeric_limits<float>::quiet_NaN();
    field.heights[(c - d) * n + (c - d + 1)] = 30.0f;
    HorizonOptions options;
    options.directions = 8;  // direction 5: azimuth 225 degrees, the step (-1, -1)
    HorizonOutputs outputs;
    outputs.horizon_angles = true;
    testing::forEachLayout([&](const ComputeContext& context) {
      for (const HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive})
        for (const double samples : {1.0, 8.0}) {
          options.method = method;
          options.samples_per_unit = samples;
          const HorizonResult r = computeHorizons(context, field, options, outputs);
          const std::size_t at = static_cast<std::size_t>(5) * n * n + c * n + c;
          EXPECT_NEAR(r.angles[at], 0.0f, 1e-6f) << "cell " << d << " along the diagonal, samples " << samples
                                                 << (method == HorizonMethod::Sweep ? " sweep" : " naive");
          // From the cell's other side, along the row of the 30 (direction 4, azimuth 180): the
          // grid point rises.
          const int row = c - d, col = n - 1;
          EXPECT_GT(r.angles[static_cast<std::size_t>(4) * n * n + row * n + col], 0.1f) << d;
        }
    });
  }
}

// Within a maximum distance D the surface at D itself counts: a wall 8 pixels away, one pixel
// thick and 50 high, rises to 25 at 7.5, so within D = 7.5 the horizon is atan(25 / 7.5) at
// distance 7.5. The sweep took only samples within D (the grid line at 7 and 0) and found 0 at
// any sampling density (the hostile probe's find: on a city with walls the sweep's sky-view factor
// within D was worse than the naive march's at 4 samples a pixel); it now takes the surface at D.
// So does the naive march, whose last step within D = 7.3 (7, or 7.25 at 4 samples a pixel) fell
// short of the wall's slope too.
TEST(HorizonKernels, TheSurfaceAtTheMaximumDistanceCounts) {
  const int w = 20, h = 5, receiver = 10;
  std::vector<float> heights(w * h, 0.0f);
  for (int row = 0; row < h; ++row) heights[row * w + 2] = 50.0f;
  const HeightField field = testing::fieldFrom(w, h, heights);
  HorizonOptions options;
  options.directions = 4;  // direction 2: azimuth 180 degrees, toward the wall
  HorizonOutputs outputs;
  outputs.horizon_angles = outputs.horizon_distances = true;
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive})
      for (const double samples : {1.0, 4.0})
        for (const auto& [distance, angle] :
             {std::pair{7.5, std::atan2(25.0, 7.5)}, std::pair{7.3, std::atan2(15.0, 7.3)},
              std::pair{8.0, std::atan2(50.0, 8.0)}, std::pair{5.0, 0.0}}) {
          options.method = method;
          options.samples_per_unit = samples;
          options.max_distance = distance;
          const HorizonResult r = computeHorizons(context, field, options, outputs);
          const std::size_t at = std::size_t(2) * w * h + 2 * w + receiver;
          const char* name = method == HorizonMethod::Sweep ? "sweep" : "naive";
          EXPECT_NEAR(r.angles[at], angle, 1e-5) << name << ", D " << distance << ", samples " << samples;
          if (angle > 0.0) {
            EXPECT_NEAR(r.distances[at], distance, 1e-5) << name << ", D " << distance;
          }
        }
  });
}

// A peak inside D counts whatever its cell's far side: two walls 50 high touching at a corner
// across the diagonal from the receiver raise the surface along it to a peak 25 high at 3.54
// pixels, in a segment that ends beyond 4.1. Within D = 4.1 (and 3.7) the sweep found the surface
// at D alone (65.7 degrees where the peak stands at 82: the window's pass took a peak only once the
// segment's far end was within reach; the second probe's find); now the peak as without D, in
// both layouts.
TEST(HorizonKernels, APeakWithinTheMaximumDistanceCountsWhereItsSegmentEndsBeyond) {
  const int n = 16, c = 4;
  std::vector<float> heights(n * n, 0.0f);
  heights[(c + 2) * n + (c + 3)] = heights[(c + 3) * n + (c + 2)] = 50.0f;
  const HeightField field = testing::fieldFrom(n, n, heights);
  HorizonOptions options;
  options.directions = 8;  // direction 1: the step (1, 1)
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  testing::forEachLayout([&](const ComputeContext& context) {
    const std::size_t at = std::size_t(1) * n * n + c * n + c;
    const float open = computeHorizons(context, field, options, outputs).angles[at];
    EXPECT_GT(open, 1.43f);  // about 82 degrees
    for (const double distance : {3.7, 4.1, 5.0}) {
      options.max_distance = distance;
      EXPECT_EQ(computeHorizons(context, field, options, outputs).angles[at], open) << "D " << distance;
    }
    options.max_distance = 0.0;
  });
}

// A cell's peak within rounding of the receiver is the receiver: along the diagonal from (1, 1)
// toward (0, 0) the surface of corners 0, 10, 10 and 9.999999 peaks a ten-millionth of the
// way from the receiver, a rounding above it: at 2 samples a pixel the sweep took it, a horizon of
// 83 degrees at a distance of 1e-7 where the surface falls away (the second probe's find: 88
// degrees on the tops of a city's walls). Peaks within a thousandth of a segment's end are left
// to the end's sample, in both layouts.
TEST(HorizonKernels, APeakWithinRoundingOfTheReceiverIsTheReceiver) {
  const HeightField field =
      testing::fieldFrom(3, 3, {0.0f, 10.0f, 0.0f, 10.0f, 9.999999f, 0.0f, 0.0f, 0.0f, 0.0f});
  HorizonOptions options;
  options.directions = 8;  // direction 5: the step (-1, -1)
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const double samples : {1.0, 2.0, 4.0}) {
      options.samples_per_unit = samples;
      EXPECT_LT(computeHorizons(context, field, options, outputs).angles[5 * 9 + 4], 1e-3f) << samples;
    }
  });
}

// The surface at D lies inside the field or nowhere: a receiver on the field's edge looking out
// within D = 0.0005 sees nothing (-90 degrees). The point at D had been tested with the sweep's
// margin of 1e-3 pixel and its height read clamped onto the border: 0 and -59 degrees there, and
// along a steep step (1, 9) the border's surface read a dozen thousandths of a pixel away (a
// wall's 42 degrees; the third probe's find).
TEST(HorizonKernels, TheSurfaceAtTheMaximumDistanceLiesInsideTheField) {
  const int n = 12;
  std::vector<float> heights(n * n);
  for (int p = 0; p < n * n; ++p) heights[p] = static_cast<float>((p * 37) % 11) - 5.0f;
  const HeightField field = testing::fieldFrom(n, n, heights);
  HorizonOptions options;
  options.directions = 8;
  options.max_distance = 0.0005;
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  testing::forEachLayout([&](const ComputeContext& context) {
    const HorizonResult r = computeHorizons(context, field, options, outputs);
    const float none = static_cast<float>(-M_PI / 2.0);
    for (int row = 0; row < n; ++row) {  // looking out of the field: direction 4 (-x) from column 0
      EXPECT_EQ(r.angles[std::size_t(4) * n * n + row * n], none) << row;
      EXPECT_EQ(r.angles[std::size_t(0) * n * n + row * n + n - 1], none) << row;  // direction 0 (+x)
    }
    EXPECT_EQ(r.angles[std::size_t(5) * n * n + 1], none);  // (1, 0) toward (-1, -1)
  });
}

TEST(HorizonKernels, AzimuthOffsetRotatesTheDirections) {
  const HeightField field = makeSyntheticField("sine", 20, 17, 1);
  HorizonOptions options;
  options.directions = 4;
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  const auto plain = computeHorizons(testContext(), field, options, outputs);
  options.azimuth_offset = M_PI / 2;
  const auto rotated = computeHorizons(testContext(), field, options, outputs);
  const std::size_t plane = field.pixelCount();
  for (int k = 0; k < 4; ++k) {
    const std::vector<float> a(rotated.angles.begin() + k * plane, rotated.angles.begin() + (k + 1) * plane);
    const int same = (k + 1) % 4;
    const std::vector<float> b(plain.angles.begin() + same * plane,
                               plain.angles.begin() + (same + 1) * plane);
    EXPECT_TRUE(nearlyEqual(a, b, 1e-5f)) << "direction " << k;
  }
}

// Finite heights whose span overflows the kernels' float products are refused (an infinite
// prepared height would turn hull comparisons into NaN).
TEST(HorizonKernels, HeightSpanBeyondFloatArithmeticIsRefused) {
  HeightField field = makeSyntheticField("noise", 5, 4, 1);
  field.heights[0] = -3e38f;
  field.heights[7] = 3e38f;
  HorizonOptions options;
  options.directions = 4;
  HorizonOutputs outputs;
  outputs.sky_view_factor = true;
  EXPECT_THROW(computeHorizons(testContext(), field, options, outputs), InvalidArgument);
  field.heights[0] = field.heights[7] = 1.0f;
  field.z_scale = 1e30;
  EXPECT_THROW(computeHorizons(testContext(), field, options, outputs), InvalidArgument);
  field.z_scale = 1e20;  // heights of noise in [0, 1): spans up to 1e20, whose squares overflow
  EXPECT_THROW(computeHorizons(testContext(), field, options, outputs), InvalidArgument);
  field.z_scale = 1e17;  // spans up to 1e17: fine
  EXPECT_NO_THROW(computeHorizons(testContext(), field, options, outputs));
  field.z_scale = 1.0;  // a cliff of 2e19 (a sky-view factor of 1 at its foot when it ran)
  field.heights[7] = 2e19f;
  EXPECT_THROW(computeHorizons(testContext(), field, options, outputs), InvalidArgument);
}

// A plateau on a cliff of 1e6 (a hard case) and of 3e7 stays flat inside: every horizon there is
// at most 0, for the sweep and the naive march, with a nodata hole in it too (the edges and grid
// points beside it), in both layouts. The weighted sum of four equal corners rounds by units in the last
// place of their height: inside the plateau of 3e7 the naive march found 63 degrees, the sweep 62
// (one unit, 2, a pixel away), and 7 degrees on 1.23e6 (`corner_bilinear` now).
TEST(HorizonKernels, APlateauOnAHighCliffStaysFlatInside) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (float top : {1.23e6f, 3e7f}) {
      HeightField field = makeSyntheticField("flat", 40, 36);
      for (int y = 6; y < 30; ++y)
        for (int x = 6; x < 34; ++x) field.heights[std::size_t(y) * 40 + x] = top;
      field.heights[17 * 40 + 20] = NAN;
      for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
        SCOPED_TRACE(std::to_string(top) + (method == HorizonMethod::Naive ? " naive" : " sweep"));
        HorizonOptions options;
        options.directions = 64;
        options.method = method;
        HorizonOutputs outputs;
        outputs.horizon_angles = true;
        const auto result = computeHorizons(context, field, options, outputs);
        float highest = -INFINITY;
        for (int k = 0; k < options.directions; ++k)
          for (int y = 9; y < 27; ++y)
            for (int x = 9; x < 31; ++x)
              highest = std::max(highest, result.angles[(std::size_t(k) * 36 + y) * 40 + x]);
        EXPECT_EQ(highest, 0.0f);
      }
    }
  });
}

// One height far below the rest (an undeclared void: -32768, -1e6) costs the others no precision:
// counted from the lowest, a plane 8848 + 0.001 column was held to steps of 1/16 beside a pixel at
// -1e6 and its horizon uphill came out up to 5 degrees where it is 0.057 (a probe's find; 0.2
// degrees beside -32768). Heights now count from the median of a lattice of them (heightBase).
TEST(HorizonKernels, OneHeightFarBelowTheRestCostsTheOthersNoPrecision) {
  const int n = 48;
  HeightField field = makeSyntheticField("flat", n, n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) field.heights[std::size_t(y) * n + x] = float(8848.0 + 0.001 * x);
  EXPECT_EQ(heightBase(field), field.heights[23]);  // the lower of the lattice's two middle heights
  HorizonOptions options;
  options.directions = 4;  // direction 0: azimuth 0, along +x, uphill
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const float pit : {-32768.0f, -1e6f}) {
      field.heights[0] = pit;
      EXPECT_EQ(heightBase(field), field.heights[23]) << pit;
      for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
        options.method = method;
        const HorizonResult r = computeHorizons(context, field, options, outputs);
        double worst = 0.0;
        for (int y = 4; y < n; ++y)
          for (int x = 4; x < n - 4; ++x) {
            // Along the row the surface is linear between grid points: the steepest of them, in
            // double, on the float32 heights (whose steps of 2^-10 make the plane's slope ragged).
            const float* row = &field.heights[std::size_t(y) * n];
            double steepest = -INFINITY;
            for (int s = x + 1; s < n; ++s)
              steepest = std::max(steepest, (double(row[s]) - row[x]) / (s - x));
            worst = std::max(worst, std::fabs(r.angles[std::size_t(y) * n + x] - std::atan(steepest)));
          }
        EXPECT_LT(worst, 1e-5) << pit << (method == HorizonMethod::Sweep ? " sweep" : " naive");
      }
    }
  });
  // The lattice's finite heights only; none finite there: the lowest finite height.
  HeightField holes = makeSyntheticField("flat", 3, 1);
  holes.heights = {NAN, 5.0f, 7.0f};
  EXPECT_EQ(heightBase(holes), 5.0f);
  holes.heights = {2.0f, NAN, 7.0f, NAN};
  holes.width = 4;
  EXPECT_EQ(heightBase(holes), 2.0f);
  holes.heights = {9.0f, NAN, -3.0f, NAN};  // lattice columns 0 .. 3 all sampled: 9, -3 -> -3
  EXPECT_EQ(heightBase(holes), -3.0f);
}

// An origin that does not place the field inside its larger field, or whose base is not finite, is
// refused; a base among the heights or above them is a base (heights count from it either way).
TEST(HorizonKernels, AnOriginOutsideItsLargerFieldOrWithoutAFiniteBaseIsRefused) {
  HeightField field = makeSyntheticField("noise", 6, 5, 1);  // heights in [0, 1)
  HorizonOptions options;
  options.directions = 4;
  options.max_distance = 2.0;
  for (const double base : {-1.0, 0.5, 7.0}) {
    field.origin = {2, 3, 8, 8, base};
    EXPECT_NO_THROW(computeHorizons(testContext(), field, options, allOutputs())) << base;
  }
  for (FieldOrigin bad :
       {FieldOrigin{3, 3, 8, 8, -1.0}, FieldOrigin{2, 4, 8, 8, -1.0}, FieldOrigin{-1, 0, 8, 8, -1.0},
        FieldOrigin{0, 0, 5, 0, -1.0}, FieldOrigin{2, 3, 8, 8, INFINITY}, FieldOrigin{2, 3, 8, 8, NAN},
        FieldOrigin{2, 3, 8, 8, -1.0, std::vector<double>(8, 1.0), std::vector<double>(8, 1.0)}}) {
    field.origin = bad;
    EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  }
  // With per-row spacing, the larger field's rows: one per row, this field's among them.
  testing::setRowSpacing(field);
  HeightField larger = makeSyntheticField("flat", 1, 8);
  testing::setRowSpacing(larger);
  std::vector<double> xs = larger.row_cell_size_x, ys = larger.row_cell_size_y;
  std::copy(field.row_cell_size_x.begin(), field.row_cell_size_x.end(), xs.begin() + 3);
  std::copy(field.row_cell_size_y.begin(), field.row_cell_size_y.end(), ys.begin() + 3);
  field.origin = {2, 3, 8, 8, -1.0, xs, ys};
  EXPECT_NO_THROW(computeHorizons(testContext(), field, options, allOutputs()));
  for (FieldOrigin bad : {FieldOrigin{2, 3, 8, 8, -1.0}, FieldOrigin{2, 3, 8, 8, -1.0, xs, {}},
                          FieldOrigin{2, 2, 8, 8, -1.0, xs, ys},
                          FieldOrigin{2, 3, 8, 8, -1.0, std::vector<double>(xs.begin(), xs.end() - 1), ys}}) {
    field.origin = bad;
    EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  }
}

TEST(HorizonKernels, InvalidOptionsAreRejectedBeforeLaunch) {
  const HeightField field = makeSyntheticField("flat", 5, 5);
  HorizonOptions options;
  options.directions = 0;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  options.directions = kMaxDirections + 1;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  options.directions = 4;
  EXPECT_THROW(computeHorizons(testContext(), field, options, HorizonOutputs{}), InvalidArgument);
  options.samples_per_unit = 0.0;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  options.samples_per_unit = 1.0;
  options.strip_rows = -1;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  options.strip_rows = 2;
  options.method = HorizonMethod::Naive;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  options.strip_rows = 0;
  options.method = HorizonMethod::Sweep;
  options.azimuth_tolerance = 0.0;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  HeightField empty;
  EXPECT_THROW(computeHorizons(testContext(), empty, HorizonOptions{}, allOutputs()), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
