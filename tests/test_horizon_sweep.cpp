// test_horizon_sweep.cpp: the hull-stack sweep and the naive march against their oracles:
// exactness on identical line samples, kernels against the scalar references, and the
// sweep against the naive march where both sample the same points.
#include <gtest/gtest.h>

#include <cmath>

#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/reference.hpp"
#include "hfvis/synthetic_fields.hpp"
#include "horizon_common.hpp"
#include "horizon_device.hpp"
#include "reference_internal.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::awkwardSizes;
using testing::nearlyEqual;
using testing::testContext;

const double kAzimuths[] = {0.0, M_PI / 2, M_PI, 3 * M_PI / 2, M_PI / 4, 0.3, 2.5, 4.0, 5.9};

HorizonOutputs allOutputs() {
  HorizonOutputs o;
  o.horizon_angles = o.horizon_distances = o.sky_view_factor = o.ambient_occlusion = true;
  return o;
}

// Exactness on a line: on the very samples the kernel took, the occluder the stack
// reports casts the same elevation as the steepest of all farther samples (brute force).
TEST(HorizonSweepLine, StackEqualsBruteForceMaximumOnEveryHardCase) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      const HeightField field = makeSyntheticField(name, w, h, 7);
      const auto prepared = detail::prepareHeights(field);
      for (double azimuth : kAzimuths) {
        SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " azimuth " + std::to_string(azimuth));
        const auto d = detail::makeSweepDirection(field, azimuth, 1.0, 1.0);
        const auto lines = detail::sweepLinesOnDevice(testContext(), field, prepared.heights, d);
        const auto reference = detail::referenceSweepLines(field, prepared.heights, d);
        ASSERT_TRUE(nearlyEqual(lines.samples, reference.samples, 0.0f)) << "presampled heights differ";
        int checked = 0;
        for (int j = 0; j < d.n_lines; ++j) {
          bool seen_farther = false;
          for (int i = 0; i < d.n_steps; ++i) {
            const std::size_t e = static_cast<std::size_t>(i) * d.n_lines + j;
            const float hq = lines.samples[e];
            if (std::isnan(hq)) continue;
            if (!seen_farther) {
              ASSERT_EQ(lines.occluder_steps[e], -1.0f) << "line " << j << " step " << i << " has no farther sample";
            } else {
              // Brute force over every farther sample of this line, in double.
              double brute = -M_PI;
              for (int k = 0; k < i; ++k) {
                const float hk = lines.samples[static_cast<std::size_t>(k) * d.n_lines + j];
                if (!std::isnan(hk)) brute = std::max(brute, std::atan2(double(hk) - hq, double(i - k)));
              }
              const float occ_step = lines.occluder_steps[e];
              ASSERT_GE(occ_step, 0.0f) << "line " << j << " step " << i;
              ASSERT_LT(occ_step, float(i));
              const double stack = std::atan2(double(lines.occluder_rises[e]), double(i) - occ_step);
              ASSERT_NEAR(stack, brute, 1e-6) << "line " << j << " step " << i;
              ++checked;
            }
            seen_farther = true;
          }
        }
        EXPECT_TRUE(nearlyEqual(lines.occluder_steps, reference.steps, 0.0f)) << "kernel and reference stacks differ";
        if (field.width > 1 && field.height > 1 && name != "nan_holes") {
          EXPECT_GT(checked, 0);
        }
      }
    }
  }
}

// Kernel results equal the scalar reference of the same algorithm, for both methods.
void expectKernelMatchesReference(HorizonMethod method, double samples_per_unit, double lines_per_unit) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h));
      HeightField field = makeSyntheticField(name, w, h, 3);
      field.cell_size_x = 1.5;
      HorizonOptions options;
      options.directions = 7;
      options.azimuth_offset = 0.1;
      options.method = method;
      options.samples_per_unit = samples_per_unit;
      options.lines_per_unit = lines_per_unit;
      const auto outputs = allOutputs();
      const auto device = computeHorizons(testContext(), field, options, outputs);
      const auto reference = referenceHorizons(field, options, outputs);
      EXPECT_TRUE(nearlyEqual(device.angles, reference.angles, 2e-5f));
      // Distances: relative to the field's extent.
      EXPECT_TRUE(nearlyEqual(device.distances, reference.distances, 1e-4f * float(w + h)));
      EXPECT_TRUE(nearlyEqual(device.sky_view_factor, reference.sky_view_factor, 1e-5f));
      EXPECT_TRUE(nearlyEqual(device.ambient_occlusion, reference.ambient_occlusion, 1e-5f));
    }
  }
}

TEST(HorizonKernels, SweepMatchesScalarReference) { expectKernelMatchesReference(HorizonMethod::Sweep, 1.0, 1.0); }

TEST(HorizonKernels, SweepMatchesScalarReferenceWithDenserSampling) {
  expectKernelMatchesReference(HorizonMethod::Sweep, 2.0, 3.0);
}

TEST(HorizonKernels, NaiveMatchesScalarReference) { expectKernelMatchesReference(HorizonMethod::Naive, 1.0, 1.0); }

// On the four axis directions the sweep's lines pass through the pixel centres, so the
// sweep and the naive march see the very same samples (with the near field sampled at the
// first step only, as the naive march does): their horizons must agree.
TEST(HorizonKernels, SweepEqualsNaiveOnAxisDirections) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h));
      const HeightField field = makeSyntheticField(name, w, h, 5);
      HorizonOptions options;
      options.directions = 4;
      options.near_field_samples = 1;
      HorizonOutputs outputs;
      outputs.horizon_angles = outputs.horizon_distances = true;
      const auto sweep = computeHorizons(testContext(), field, options, outputs);
      options.method = HorizonMethod::Naive;
      const auto naive = computeHorizons(testContext(), field, options, outputs);
      EXPECT_TRUE(nearlyEqual(sweep.angles, naive.angles, 1e-5f));
      EXPECT_TRUE(nearlyEqual(sweep.distances, naive.distances, 1e-3f));
    }
  }
}

TEST(HorizonKernels, BatchingUnderATinyMemoryBudgetChangesNothing) {
  const HeightField field = makeSyntheticField("noise", 40, 41, 9);
  HorizonOptions options;
  options.directions = 9;
  const auto outputs = allOutputs();
  const auto whole = computeHorizons(testContext(), field, options, outputs);
  int batches = 0;
  options.memory_budget_bytes = 200 * 1024;  // a few directions per batch
  options.progress = [&](int, int) { ++batches; };
  const auto batched = computeHorizons(testContext(), field, options, outputs);
  EXPECT_GT(batches, 2);
  EXPECT_TRUE(nearlyEqual(batched.angles, whole.angles, 0.0f));
  EXPECT_TRUE(nearlyEqual(batched.sky_view_factor, whole.sky_view_factor, 1e-6f));
  EXPECT_TRUE(nearlyEqual(batched.ambient_occlusion, whole.ambient_occlusion, 1e-6f));
  options.memory_budget_bytes = 1024;
  EXPECT_THROW(computeHorizons(testContext(), field, options, outputs), MemoryBudgetError);
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
    const std::vector<float> b(plain.angles.begin() + same * plane, plain.angles.begin() + (same + 1) * plane);
    EXPECT_TRUE(nearlyEqual(a, b, 1e-5f)) << "direction " << k;
  }
}

TEST(HorizonKernels, InvalidOptionsAreRejectedBeforeLaunch) {
  const HeightField field = makeSyntheticField("flat", 5, 5);
  HorizonOptions options;
  options.directions = 0;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  options.directions = 4;
  EXPECT_THROW(computeHorizons(testContext(), field, options, HorizonOutputs{}), InvalidArgument);
  options.samples_per_unit = 0.0;
  EXPECT_THROW(computeHorizons(testContext(), field, options, allOutputs()), InvalidArgument);
  HeightField empty;
  EXPECT_THROW(computeHorizons(testContext(), empty, HorizonOptions{}, allOutputs()), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
