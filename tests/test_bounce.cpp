// test_bounce.cpp: the one-bounce gather (hfvis/bounce.hpp): the kernel against its scalar
// reference line by line and pixel by pixel; the reference against a brute-force gather that
// finds the visible samples and their elevation bands by definition, without the tree;
// closed forms (a flat plane gathers nothing; a V valley between plateaus); linearity, the
// bound against the sky that ambient occlusion sees, nodata, bad radiance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/chord_side.hpp"
#include "core/lattice_geometry.hpp"
#include "core/tree_peaks.hpp"
#include "hfvis/bounce.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis_testing/bounce_reference.hpp"
#include "hfvis_testing/sight_along_line.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "ops/bounce_internal.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::awkwardSizes;
using testing::fieldFrom;
using testing::nearlyEqual;
using testing::testContext;

// Two axis steps and three off the axes.
const std::pair<int, int> kSteps[] = {{1, 0}, {0, -1}, {1, 1}, {-4, 3}, {-2, -3}};

// The tree direction of step (a, b), one of K equal directions, at S samples per unit.
detail::TreeDirection treeStep(const HeightField& field, std::pair<int, int> step, int directions,
                               double samples_per_unit = 1.0) {
  detail::LatticeDirection lattice = detail::latticeStep(field, step.first, step.second);
  lattice.weight = 1.0 / directions;
  return detail::makeTreeDirection(field, lattice, samples_per_unit, directions);
}

// Random exit radiance in [0, 2) per channel (fixed seed).
ExitRadiance randomRadiance(const HeightField& field, int channels, std::uint32_t seed) {
  ExitRadiance radiance;
  radiance.width = field.width;
  radiance.height = field.height;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 2.0f);
  for (int c = 0; c < channels; ++c) {
    radiance.channels.emplace_back(field.pixelCount());
    for (float& v : radiance.channels.back()) v = value(rng);
  }
  return radiance;
}

ExitRadiance uniformRadiance(const HeightField& field, std::vector<float> values) {
  ExitRadiance radiance;
  radiance.width = field.width;
  radiance.height = field.height;
  for (float v : values) radiance.channels.emplace_back(field.pixelCount(), v);
  return radiance;
}

// Tolerance for gathered sums: the kernels' and the C++ library's atan2, sin and cos
// differ in the last bits (OpenCL allows a few ulp), and bands are differences of G.
float gatherTolerance(const std::vector<float>& values) {
  float largest = 0.0f;
  for (float v : values)
    if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
  return 2e-5f * largest + 1e-6f;
}

// ---------------------------------------------------------------------------------------
// Brute force on one line: visibility by its definition, bands by their definition.

// G of bounce.hpp in double: the wedge integral of the projected solid angle up to theta.
struct Wedge {
  double nz_term, nh_term, tangent;
  double g(double theta) const {
    const double t = std::max(theta, tangent);
    return nz_term * std::sin(t) * std::sin(t) + nh_term * 0.5 * (t + std::sin(t) * std::cos(t));
  }
};

Wedge wedgeFor(const float* normal, double cos_az, double sin_az, double sector) {
  Wedge w;
  const double toward = normal[0] * cos_az + normal[1] * sin_az;
  w.nz_term = normal[2] * sector / 2.0;
  w.nh_term = toward * 2.0 * std::sin(sector / 2.0);
  w.tangent = std::atan2(-w.nh_term, 2.0 * w.nz_term);
  return w;
}

// Expected irradiance of every present receiver entry of line j: for receiver r, node x
// (farther; a sample, or a peak of the surface between two samples:
// detail::IntervisibilityLines) is visible when no present node strictly between lies strictly
// above the chord x-r, or, a sample, when the steepest of them hides it only within the heights'
// rounding, as it does every hidden sample between them (the tie rule, as
// tests/test_intervisibility.cpp's brute force takes it). The visible nodes' elevations split
// into bands: at the mean elevation between two visible nodes with no hidden sample between
// them, else at the nearer one's elevation; the nearest visible node's band reaches down to
// the tangent elevation. A peak's radiance lies between its two samples' as its position does.
// `sector`: the direction's wedge of azimuth.
void expectBruteForceGather(const detail::BounceLineView& view, double sector) {
  const auto& d = view.lines.geometry;
  const int channels = view.bounce.channels, stride = channels + detail::kBounceNormalFloats;
  const int every = view.lines.receiver_every;
  const double ground = view.bounce.step_ground;
  const int shift = view.lines.position_shift;
  for (int j = 0; j < d.n_lines; ++j) {
    struct Node {
      int step;           // of the sample, or of the sample after the peak
      float h, position;  // position in 2^-shift steps
      bool peak;
    };
    std::vector<Node> nodes;
    for (int i = 0; i < d.n_steps; ++i) {
      const std::size_t e = std::size_t(i) * d.n_lines + j;
      const float h = view.lines.samples[e];
      if (shift > 0 && i > 0 &&
          detail::tree_peak_inserted(view.lines.samples[e - d.n_lines], view.lines.peaks[e], h,
                                     view.lines.peak_offsets[e], 1 << shift))
        nodes.push_back(
            {i, view.lines.peaks[e], float(((i - 1) << shift) + view.lines.peak_offsets[e]), true});
      if (!std::isnan(h)) nodes.push_back({i, h, float(i << shift), false});
    }
    auto height = [&](int k) { return nodes[k].h; };
    for (int r = 0; r < static_cast<int>(nodes.size()); ++r) {
      if (nodes[r].peak || nodes[r].step % every != every - 1) continue;  // not a receiver
      const std::size_t er = std::size_t(nodes[r].step) * d.n_lines + j;
      // Visible flags: exactly, or within the heights' rounding (the tie rule).
      std::vector<LineNode> line(static_cast<std::size_t>(r) + 1);
      for (int k = 0; k <= r; ++k) line[k] = {nodes[k].h, nodes[k].position, nodes[k].peak};
      const LineSight sight = sightAlongLine(line, static_cast<std::size_t>(r), view.lines.height_base);
      std::vector<bool> visible(r, false);
      for (int x = 0; x < r; ++x) visible[x] = sight.exactly[x] || sight.forgiven[x];
      auto adjacent = [&](int a, int b) {  // no hidden sample between visible samples a < b
        for (int k = a + 1; k < b; ++k)
          if (!visible[k] && !nodes[k].peak) return false;
        return true;
      };
      // Visible nodes, farthest first: samples seen exactly or within the rounding, peaks seen
      // exactly (they are never forgiven).
      std::vector<int> seen;
      for (int x = 0; x < r; ++x)
        if (nodes[x].peak ? sight.exactly[x] : visible[x]) seen.push_back(x);
      const Wedge w =
          wedgeFor(&view.bounce.attributes[er * stride + channels], d.cos_azimuth, d.sin_azimuth, sector);
      std::vector<double> theta(seen.size());
      for (std::size_t v = 0; v < seen.size(); ++v)
        theta[v] =
            std::atan2(double(height(seen[v])) - height(r),
                       std::ldexp(double(nodes[r].position) - nodes[seen[v]].position, -shift) * ground);
      // A node's radiance: a sample's own; a peak's between its two samples', as its position.
      auto radiance = [&](int x, int c) {
        const std::size_t after = std::size_t(nodes[x].step) * d.n_lines + j;
        const double r1 = view.bounce.attributes[after * stride + c];
        if (!nodes[x].peak) return r1;
        const double r0 = view.bounce.attributes[(after - d.n_lines) * stride + c];
        const double toward = std::ldexp(double(nodes[x].position), -shift) - (nodes[x].step - 1);
        return r0 + toward * (r1 - r0);
      };
      std::vector<double> expected(channels, 0.0);
      for (std::size_t v = 0; v < seen.size(); ++v) {
        // Neighbours in the visible order: farther (v - 1) and nearer (v + 1); adjacent
        // when no hidden node lies between them.
        double hi = theta[v], lo = theta[v];
        if (v > 0 && adjacent(seen[v - 1], seen[v])) hi = 0.5 * (theta[v - 1] + theta[v]);
        if (v + 1 < seen.size())
          lo = adjacent(seen[v], seen[v + 1]) ? 0.5 * (theta[v] + theta[v + 1]) : theta[v + 1];
        else
          lo = w.tangent;  // the nearest: down to the tangent (the surface between the receiver and it)
        for (int c = 0; c < channels; ++c) expected[c] += radiance(seen[v], c) * (w.g(hi) - w.g(lo));
      }
      for (int c = 0; c < channels; ++c) {
        const float actual = view.bounce.irradiance[er * channels + c];
        ASSERT_NEAR(actual, expected[c], 2e-5 * (1.0 + std::abs(expected[c])))
            << "line " << j << " receiver step " << nodes[r].step << " channel " << c;
      }
    }
  }
}

TEST(BounceLine, KernelEqualsReferenceAndBruteForceOnEveryHardCase) {
  int compared = 0;
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      HeightField field = makeSyntheticField(name, w, h, 7);
      field.cell_size_x = 1.5;
      const int channels = 1 + (w + h) % 3;
      const detail::BounceInputs inputs =
          detail::prepareBounce(field, randomRadiance(field, channels, w * 31 + h));
      for (auto step : kSteps) {
        SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " step " +
                     std::to_string(step.first) + "," + std::to_string(step.second));
        const auto d = treeStep(field, step, 8);
        const auto ref = detail::referenceBounceLines(field, inputs, d);
        const LineLayout layout = compared % 2 ? LineLayout::StepMajor : LineLayout::LineMajor;
        const auto dev = detail::bounceLinesOnDevice(testContext(layout), field, inputs, d);
        ASSERT_TRUE(nearlyEqual(dev.lines.samples, ref.lines.samples, 0.0f));
        ASSERT_TRUE(nearlyEqual(dev.lines.counts, ref.lines.counts, 0.0f));
        ASSERT_TRUE(nearlyEqual(dev.bounce.irradiance, ref.bounce.irradiance,
                                gatherTolerance(ref.bounce.irradiance)));
        expectBruteForceGather(ref, 2.0 * M_PI / 8);
        if (::testing::Test::HasFatalFailure()) return;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 350);
}

TEST(BounceLine, ReferenceEqualsBruteForceOnLongRandomLinesAndDenseSampling) {
  std::mt19937 rng(3);
  for (int kind = 0; kind < 3; ++kind) {
    const int w = 201, h = 4;
    const HeightField field = fieldFrom(w, h, testing::randomLineHeights(kind, w, h, 30.0f, rng));
    const auto inputs = detail::prepareBounce(field, randomRadiance(field, 2, kind));
    for (auto step : {std::pair<int, int>{1, 0}, {-1, 0}, {20, 1}}) {
      SCOPED_TRACE("kind " + std::to_string(kind) + " step " + std::to_string(step.first));
      expectBruteForceGather(detail::referenceBounceLines(field, inputs, treeStep(field, step, 16)),
                             2.0 * M_PI / 16);
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  const HeightField noise = makeSyntheticField("noise", 23, 17, 4);
  const auto inputs = detail::prepareBounce(noise, randomRadiance(noise, 1, 9));
  expectBruteForceGather(detail::referenceBounceLines(noise, inputs, treeStep(noise, {1, 2}, 5, 3.0)),
                         2.0 * M_PI / 5);
}

// ---------------------------------------------------------------------------------------
// Whole operation.

// In the default tuning of the tree, and in Algorithm 1's walk and with the safe zone every
// other field (the gather must not depend on how the tree is maintained).
TEST(BounceKernels, DeviceMatchesReference) {
  int field_index = 0;
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      const char* tuning = ++field_index % 2 ? "plain" : "zone";
      SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h));
      HeightField field = makeSyntheticField(name, w, h, 3);
      field.cell_size_y = 0.75;
      BounceOptions options;
      options.directions = 7;
      options.azimuth_offset = 0.1;
      options.samples_per_unit = name == "sine" ? 2.0 : 1.0;
      const ExitRadiance radiance = randomRadiance(field, 3, w + h);
      // The layouts alternate from field to field.
      const auto& context = testContext(field_index % 2 ? LineLayout::StepMajor : LineLayout::LineMajor);
      const auto device = computeBounce(context, field, radiance, options);
      const auto reference = referenceBounce(field, radiance, options);
      ASSERT_EQ(device.irradiance.size(), 3u);
      BounceOptions tuned = options;
      tuned.tree = *hullTreeTuningNamed(tuning);
      const auto device_tuned = computeBounce(context, field, radiance, tuned);
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(nearlyEqual(device.irradiance[c], reference.irradiance[c],
                                gatherTolerance(reference.irradiance[c])));
        // The same visits in the same order: equal bit for bit (NaN where nodata).
        EXPECT_TRUE(nearlyEqual(device_tuned.irradiance[c], device.irradiance[c], 0.0f)) << tuning;
      }
    }
  }
}

TEST(BounceAnalytic, FlatPlaneGathersNothing) {
  const HeightField field = makeSyntheticField("flat", 31, 20);
  BounceOptions options;
  options.directions = 16;
  const auto result = computeBounce(testContext(), field, uniformRadiance(field, {1.0f, 5.0f}), options);
  for (const auto& channel : result.irradiance)
    for (float v : channel) ASSERT_EQ(v, 0.0f);
}

// A V valley between two plateaus, constant along the rows: h = H on the left plateau
// (x <= xl), falling with slope a to the floor at x0, rising back to H at xr, then flat.
// Heights are piecewise linear between pixel columns, so the bilinear surface is exact.
struct Valley {
  int x0 = 20, xl = 8, xr = 32;
  float a = 1.0f, top = 12.0f;
  float at(int x) const {
    if (x <= xl || x >= xr) return top;
    return a * std::abs(float(x - x0));
  }
  HeightField field(int width, int height) const {
    std::vector<float> h;
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c) h.push_back(at(c));
    return fieldFrom(width, height, h);
  }
};

// The receiver on the right flank looks across the valley (direction pi) and sees the left
// flank up to its rim; the plateau behind the rim is hidden, and its own flank lies in its
// tangent plane. Along the rows (pi/2, 3pi/2) everything is level: those bands are empty. Up its
// own flank (direction 0) the samples are collinear at the flank's elevation, which the wedge's
// clip theta_t lies a little below (the wedge's cosine factor, 2 sin(D/2) / D of the slope's
// tangent): that band is the one ambient occlusion misses there, so E / (pi L) + AO stays 1. So
// with uniform radiance L, E = L * (G(theta_rim) - G(theta_t)) in direction pi plus
// L * (G(atan a') - G(theta_t)) in direction 0, G and theta_t of bounce.hpp with the flank's
// normal (-a', 0, 1) / |.|, a' = a * z_scale / cell_x the ground slope.
TEST(BounceAnalytic, VValleyAcrossTheAxes) {
  const Valley valley;
  HeightField field = valley.field(41, 9);
  field.cell_size_x = 2.0;
  field.cell_size_y = 0.5;
  field.z_scale = 3.0;
  const int col = 26, row = 4;
  BounceOptions options;
  options.directions = 4;
  const std::vector<float> radiance_values = {0.7f, 1.0f, 2.5f};
  const auto device = computeBounce(testContext(), field, uniformRadiance(field, radiance_values), options);
  const auto reference = referenceBounce(field, uniformRadiance(field, radiance_values), options);

  const double slope = valley.a * field.z_scale / field.cell_size_x;
  const float normal[3] = {float(-slope / std::hypot(slope, 1.0)), 0.0f, float(1.0 / std::hypot(slope, 1.0))};
  const Wedge w = wedgeFor(normal, -1.0, 0.0, 2.0 * M_PI / 4);
  const double rise = (valley.top - valley.at(col)) * field.z_scale;
  const double theta_rim = std::atan2(rise, (col - valley.xl) * field.cell_size_x);
  ASSERT_GT(w.tangent, -std::atan(slope)) << "the own flank must lie below the clip";
  const Wedge up = wedgeFor(normal, 1.0, 0.0, 2.0 * M_PI / 4);
  ASSERT_LT(up.tangent, std::atan(slope));
  const double own = up.g(std::atan(slope)) - up.g(up.tangent);
  EXPECT_LT(own, 1e-2);
  const double per_unit = w.g(theta_rim) - w.g(w.tangent) + own;
  EXPECT_GT(per_unit, 0.1);
  for (std::size_t c = 0; c < radiance_values.size(); ++c) {
    const std::size_t p = std::size_t(row) * field.width + col;
    EXPECT_NEAR(device.irradiance[c][p], radiance_values[c] * per_unit, 1e-5 * radiance_values[c]) << c;
    EXPECT_NEAR(reference.irradiance[c][p], radiance_values[c] * per_unit, 1e-5 * radiance_values[c]) << c;
  }
}

// The same valley seen in 32 directions, off the axes too. The expectation is computed from
// the receiver's own ray (the samples the naive method takes), with the profile's closed
// form: per direction, L * (G(highest elevation) - G(theta_t)) (the nearest sample lies on
// the own flank, below the clip). The sweep's directions are lattice steps near phi_k with
// quadrature weights, not phi_k itself: 1 % tolerance.
TEST(BounceAnalytic, VValleyInManyDirections) {
  const Valley valley;
  const HeightField field = valley.field(41, 121);
  const int col = 26, row = 60;
  BounceOptions options;
  options.directions = 32;
  options.azimuth_offset = 0.05;
  const auto result = computeBounce(testContext(), field, uniformRadiance(field, {1.0f}), options);
  const double slope = valley.a;
  const float normal[3] = {float(-slope / std::hypot(slope, 1.0)), 0.0f, float(1.0 / std::hypot(slope, 1.0))};
  double expected = 0.0;
  for (int k = 0; k < options.directions; ++k) {
    const double phi = directionAzimuth(k, options);
    const Wedge w = wedgeFor(normal, std::cos(phi), std::sin(phi), 2.0 * M_PI / options.directions);
    double highest = -M_PI / 2;
    for (int i = 1;; ++i) {
      const double x = col + i * std::cos(phi), y = row + i * std::sin(phi);
      if (x < 0 || x > field.width - 1 || y < 0 || y > field.height - 1) break;
      const int x_lo = std::min(int(std::floor(x)), field.width - 2);
      const double f = x - x_lo;
      const double h = (1 - f) * valley.at(x_lo) + f * valley.at(x_lo + 1);
      highest = std::max(highest, std::atan2(h - valley.at(col), double(i)));
    }
    expected += w.g(highest) - w.g(w.tangent);
  }
  const float actual = result.irradiance[0][std::size_t(row) * field.width + col];
  std::printf("V valley, K = 32: E = %.5f, from the receiver's own rays %.5f (%+.3f %%)\n", actual, expected,
              100.0 * (actual - expected) / expected);
  EXPECT_NEAR(actual, expected, 0.01 * expected);
}

// E is linear in the radiance: channel 2 = 2 * channel 0 + channel 1, channel 3 = channel 1 / 4
// (four channels, the most one run gathers).
TEST(BounceKernels, GatherIsLinearInTheRadiance) {
  const HeightField field = makeSyntheticField("sine", 40, 41, 2);
  ExitRadiance radiance = randomRadiance(field, 2, 5);
  radiance.channels.emplace_back(field.pixelCount());
  radiance.channels.emplace_back(field.pixelCount());
  for (std::size_t p = 0; p < field.pixelCount(); ++p) {
    radiance.channels[2][p] = 2.0f * radiance.channels[0][p] + radiance.channels[1][p];
    radiance.channels[3][p] = 0.25f * radiance.channels[1][p];
  }
  BounceOptions options;
  options.directions = 12;
  const auto result = computeBounce(testContext(), field, radiance, options);
  ASSERT_EQ(result.irradiance.size(), 4u);
  std::vector<float> combined(field.pixelCount()), quarter(field.pixelCount());
  for (std::size_t p = 0; p < combined.size(); ++p) {
    combined[p] = 2.0f * result.irradiance[0][p] + result.irradiance[1][p];
    quarter[p] = 0.25f * result.irradiance[1][p];
  }
  EXPECT_TRUE(nearlyEqual(result.irradiance[2], combined, gatherTolerance(combined)));
  EXPECT_TRUE(nearlyEqual(result.irradiance[3], quarter, gatherTolerance(quarter)));
  const auto reference = referenceBounce(field, radiance, options);
  for (int c = 0; c < 4; ++c)
    EXPECT_TRUE(
        nearlyEqual(result.irradiance[c], reference.irradiance[c], gatherTolerance(reference.irradiance[c])));
}

// Bounds on real terrain (a crop of the bundled fractal): 0 <= E, and with uniform radiance
// 1 the bounce and the sky together fill at most the hemisphere: E / pi + AO <= 1 (AO of the
// horizon sweep, the same G above the horizon; slack for the two operations' different
// samples and the fast atan). Also: some pixels must gather a lot, or the test could pass with E = 0.
TEST(BounceKernels, BounceAndSkyFillAtMostTheHemisphere) {
  const HeightField fractal = readHeightField(std::string(HFVIS_DATA_DIR) + "/fractal_256.exr");
  HeightField field = makeSyntheticField("flat", 48, 40);
  for (int r = 0; r < field.height; ++r)
    for (int c = 0; c < field.width; ++c) field.heights[r * field.width + c] = fractal.at(c + 60, r + 90);
  BounceOptions options;
  options.directions = 16;
  const auto bounce = computeBounce(testContext(), field, uniformRadiance(field, {1.0f}), options);
  HorizonOptions horizon_options;
  horizon_options.directions = 16;
  HorizonOutputs outputs;
  outputs.ambient_occlusion = true;
  const auto horizons = computeHorizons(testContext(), field, horizon_options, outputs);
  double largest = 0.0, worst = 0.0;
  for (std::size_t p = 0; p < field.pixelCount(); ++p) {
    const double e = bounce.irradiance[0][p] / M_PI, ao = horizons.ambient_occlusion[p];
    ASSERT_GE(e, -1e-6) << p;
    largest = std::max(largest, e);
    worst = std::max(worst, e + ao);
  }
  std::printf("fractal crop, K = 16: largest E / pi %.3f, largest E / pi + AO %.4f\n", largest, worst);
  EXPECT_GT(largest, 0.05);
  EXPECT_LE(worst, 1.02);
}

// A pixel whose nearest visible sample is its horizon sees surface from its tangent up to it:
// at the bottom of a pit of 2 x 2 pixels, beside a wall and in a trench, with uniform radiance
// 1, E / pi + AO is 1 (the surface below the horizon, the sky above). Their bands had ended at
// the nearest sample's elevation: E was 0 there (a probe's find). At the bottom of a pit of one
// pixel the rim of its own cells (a peak between samples) hides every sample off the axes: the
// rim shows there, with the radiance between its two samples (it had gathered nothing: 0.19
// against 3.06 at K = 64, a probe's find).
TEST(BounceKernels, APitsBottomAndAWallsFootGatherTheSurfaceBelowTheirHorizon) {
  HeightField field = makeSyntheticField("flat", 24, 20);
  for (int r = 6; r < 8; ++r)
    for (int c = 6; c < 8; ++c) field.heights[std::size_t(r) * 24 + c] = -5.0f;  // a pit
  field.heights[std::size_t(4) * 24 + 14] = -5.0f;                               // a pit of one pixel
  for (int c = 0; c < 24; ++c) field.heights[std::size_t(14) * 24 + c] = 10.0f;  // a wall along row 14
  for (int r = 0; r < 10; ++r) field.heights[std::size_t(r) * 24 + 18] = -3.0f;  // a trench, column 18
  BounceOptions options;
  options.directions = 64;
  HorizonOptions horizon_options;
  horizon_options.directions = 64;
  HorizonOutputs outputs;
  outputs.ambient_occlusion = true;
  testing::forEachLayout([&](const ComputeContext& context) {
    const auto bounce = computeBounce(context, field, uniformRadiance(field, {1.0f}), options);
    const auto horizons = computeHorizons(context, field, horizon_options, outputs);
    for (const auto& [col, row] :
         {std::pair{6, 6}, std::pair{6, 13}, std::pair{12, 15}, std::pair{18, 4}, std::pair{14, 4}}) {
      const std::size_t p = std::size_t(row) * 24 + col;
      const double e = bounce.irradiance[0][p] / M_PI, ao = horizons.ambient_occlusion[p];
      EXPECT_GT(e, 0.1) << col << "," << row;
      EXPECT_NEAR(e + ao, 1.0, 0.02) << col << "," << row;
    }
  });
}

TEST(BounceKernels, NodataNeitherEmitsNorReceives) {
  const HeightField field = makeSyntheticField("nan_holes", 33, 20, 2);
  BounceOptions options;
  options.directions = 8;
  ExitRadiance radiance = randomRadiance(field, 1, 1);
  for (std::size_t p = 0; p < field.pixelCount(); ++p)
    if (std::isnan(field.heights[p])) radiance.channels[0][p] = std::nanf("");  // ignored there
  const auto result = computeBounce(testContext(), field, radiance, options);
  for (std::size_t p = 0; p < field.pixelCount(); ++p) {
    ASSERT_EQ(std::isnan(result.irradiance[0][p]), std::isnan(field.heights[p])) << p;
    if (!std::isnan(field.heights[p])) {
      ASSERT_GE(result.irradiance[0][p], -1e-6f);
    }
  }
  const auto reference = referenceBounce(field, radiance, options);
  EXPECT_TRUE(
      nearlyEqual(result.irradiance[0], reference.irradiance[0], gatherTolerance(reference.irradiance[0])));
}

TEST(BounceKernels, BatchingUnderATinyMemoryBudgetChangesNothing) {
  const HeightField field = makeSyntheticField("noise", 40, 41, 9);
  const ExitRadiance radiance = randomRadiance(field, 2, 4);
  testing::forEachLayout([&](const ComputeContext& context) {
    BounceOptions options;
    options.directions = 9;
    const auto whole = computeBounce(context, field, radiance, options);
    int reports = 0;
    // The planes (heights, normals, 2 radiance and 2 irradiance channels) take 8 * 4 * 1640
    // bytes; the tree scratch (24 bytes a slot with the peaks' prepass, two slots a step: at
    // least 3280 slots per direction) gets room for about 466: every direction runs in chunks
    // of lines.
    options.memory_budget_bytes = 8 * 4 * 1640 + 16 * 700;
    options.progress = [&](int, int) { ++reports; };
    const auto batched = computeBounce(context, field, radiance, options);
    EXPECT_EQ(reports, 9);
    for (int c = 0; c < 2; ++c)  // the same visits in the same order: bit for bit
      EXPECT_TRUE(nearlyEqual(batched.irradiance[c], whole.irradiance[c], 0.0f));
    options.memory_budget_bytes = 1024;
    EXPECT_THROW(computeBounce(context, field, radiance, options), MemoryBudgetError);
  });
}

TEST(BounceKernels, BadRadianceIsRejectedBeforeLaunch) {
  const HeightField field = makeSyntheticField("noise", 9, 7);
  BounceOptions options;
  options.directions = 4;
  ExitRadiance radiance = randomRadiance(field, 1, 1);
  radiance.width = 8;
  EXPECT_THROW(computeBounce(testContext(), field, radiance, options), InvalidArgument);
  EXPECT_THROW(computeBounce(testContext(), field, randomRadiance(field, 0, 1), options), InvalidArgument);
  EXPECT_THROW(computeBounce(testContext(), field, randomRadiance(field, 5, 1), options), InvalidArgument);
  radiance = randomRadiance(field, 2, 1);
  radiance.channels[1][10] = std::nanf("");
  try {
    computeBounce(testContext(), field, radiance, options);
    ADD_FAILURE() << "NaN radiance accepted";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("(1, 1)"), std::string::npos) << error.what();
  }
  radiance.channels[1][10] = -1.0f;
  EXPECT_THROW(computeBounce(testContext(), field, radiance, options), InvalidArgument);
  // (3e38 overflowed the gather's sums, and the message blamed the heights)
  radiance.channels[1][10] = 3e38f;
  try {
    computeBounce(testContext(), field, radiance, options);
    ADD_FAILURE() << "a radiance of 3e38 accepted";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("at most 1e30"), std::string::npos) << error.what();
  }
  radiance.channels[1][10] = 1.0f;
  radiance.channels[1].pop_back();
  EXPECT_THROW(computeBounce(testContext(), field, radiance, options), InvalidArgument);
  options.directions = 0;
  EXPECT_THROW(computeBounce(testContext(), field, randomRadiance(field, 1, 1), options), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
