// test_horizon_analytic.cpp: horizons, sky-view factor and ambient occlusion on fields
// with a closed-form answer (docs/TESTING.md: "analytic cases"), for both methods.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hfvis/horizon.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis_testing/horizon_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "core/lattice_geometry.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::testContext;

class HorizonAnalytic : public ::testing::TestWithParam<HorizonMethod> {
 protected:
  HorizonResult run(const HeightField& field, int directions, HorizonOutputs outputs, double curvature = 0.0,
                    double max_distance = 0.0) {
    HorizonOptions options;
    options.directions = directions;
    options.curvature = curvature;
    options.max_distance = max_distance;
    options.method = GetParam();
    return computeHorizons(testContext(), field, options, outputs);
  }
  static HorizonOutputs everything() {
    HorizonOutputs o;
    o.horizon_angles = o.horizon_distances = o.sky_view_factor = o.ambient_occlusion = true;
    return o;
  }
};

TEST_P(HorizonAnalytic, FlatPlaneHasZeroHorizonInsideAndSkyViewAndOcclusionOfOne) {
  const HeightField field = makeSyntheticField("flat", 19, 14);
  const auto r = run(field, 8, everything());
  const std::size_t plane = field.pixelCount();
  for (int k = 0; k < 8; ++k) {
    for (int row = 1; row < field.height - 1; ++row)
      for (int c = 1; c < field.width - 1; ++c)
        ASSERT_NEAR(r.angles[k * plane + row * field.width + c], 0.0f, 1e-6)
            << "k " << k << " at " << c << "," << row;
  }
  // Every direction: a pixel whose ray leaves the field at once sees nothing (-pi/2); one
  // whose ray meets the plane sees it level (0).
  for (int k = 0; k < 8; ++k) {
    const double dx = std::cos(M_PI * k / 4), dy = std::sin(M_PI * k / 4);
    for (int row = 0; row < field.height; ++row) {
      for (int c = 0; c < field.width; ++c) {
        const double x = c + dx, y = row + dy;
        const bool leaves =
            x < -1e-3 || y < -1e-3 || x > field.width - 1 + 1e-3 || y > field.height - 1 + 1e-3;
        ASSERT_NEAR(r.angles[k * plane + row * field.width + c], leaves ? -M_PI / 2 : 0.0, 1e-6)
            << "k " << k << " at " << c << "," << row;
      }
    }
  }
  // Axis directions: the edge pixel facing out sees nothing (-pi/2), its neighbour 0.
  for (int row = 0; row < field.height; ++row) {
    EXPECT_FLOAT_EQ(r.angles[0 * plane + row * field.width + field.width - 1], -M_PI / 2);
    EXPECT_FLOAT_EQ(r.angles[4 * plane + row * field.width + 0], -M_PI / 2);
    EXPECT_FLOAT_EQ(r.angles[0 * plane + row * field.width + field.width - 2], 0.0f);
  }
  for (std::size_t p = 0; p < plane; ++p) {
    ASSERT_NEAR(r.sky_view_factor[p], 1.0f, 1e-6);
    ASSERT_NEAR(r.ambient_occlusion[p], 1.0f, 1e-5);
  }
}

// A wall of height 10 from column 30 on, seen from the ground in front of it along +x:
// horizon atan(z * 10 / (cell_x * (30 - c))), cast from the foot of the wall's top.
TEST_P(HorizonAnalytic, LongWallCastsAtanOfHeightOverDistance) {
  HeightField field = makeSyntheticField("flat", 40, 9);
  for (int row = 0; row < field.height; ++row)
    for (int c = 30; c < field.width; ++c) field.heights[row * field.width + c] += 10.0f;
  field.cell_size_x = 2.0;
  field.z_scale = 3.0;
  HorizonOutputs outputs;
  outputs.horizon_angles = outputs.horizon_distances = true;
  const auto r = run(field, 4, outputs);
  for (int row = 0; row < field.height; ++row) {
    for (int c = 0; c < 30; ++c) {
      const std::size_t p = row * field.width + c;
      EXPECT_NEAR(r.angles[p], std::atan(30.0 / (2.0 * (30 - c))), 1e-5) << c << "," << row;
      EXPECT_NEAR(r.distances[p], 2.0 * (30 - c), 1e-3) << c << "," << row;
    }
  }
}

// Within a maximum distance D the wall is seen only from where its top is at most D away;
// farther receivers see flat ground (horizon 0, cast from within D), but for the foot of its
// slope, which the bilinear surface ramps up from column 29 to 30: where D ends on it, both
// methods see the surface there, at D (the naive march's whole-pixel steps lie on the flat).
TEST_P(HorizonAnalytic, LongWallBeyondTheMaximumDistanceIsNotSeen) {
  HeightField field = makeSyntheticField("flat", 40, 9);
  for (int row = 0; row < field.height; ++row)
    for (int c = 30; c < field.width; ++c) field.heights[row * field.width + c] += 10.0f;
  field.cell_size_x = 2.0;
  HorizonOutputs outputs;
  outputs.horizon_angles = outputs.horizon_distances = true;
  for (double max_distance : {7.0, 19.0}) {
    SCOPED_TRACE("max distance " + std::to_string(max_distance));
    const auto r = run(field, 4, outputs, 0.0, max_distance);
    for (int row = 0; row < field.height; ++row) {
      for (int c = 0; c < 30; ++c) {
        const std::size_t p = row * field.width + c;
        const double d = 2.0 * (30 - c);
        if (d <= max_distance) {
          EXPECT_NEAR(r.angles[p], std::atan(10.0 / d), 1e-5) << c << "," << row;
          EXPECT_NEAR(r.distances[p], d, 1e-3) << c << "," << row;
        } else {
          const double foot = c + max_distance / 2.0 - 29.0;  // how far up the slope D ends
          const bool on_slope = foot > 0.0;
          EXPECT_NEAR(r.angles[p], on_slope ? std::atan(10.0 * foot / max_distance) : 0.0, 1e-6)
              << c << "," << row;
          EXPECT_LE(r.distances[p], max_distance) << c << "," << row;
          if (on_slope) {
            EXPECT_NEAR(r.distances[p], max_distance, 1e-4) << c << "," << row;
          }
        }
      }
    }
  }
}

// A latitude / longitude grid's spacing per row: a wall of height 10 from column 30 on, each row
// r with its own spacing along columns dx(r) = 2 + 0.5 r (as east-west spacing shrinks with
// latitude): seen along +x at atan(10 / ((30 - c) dx(r))) from that distance. And a wall across
// the rows from row 30 on, with spacing along rows dy(r) = 1 + 0.05 r: seen along +y from the
// ground length between the rows, the sum of dy at the half rows between.
TEST_P(HorizonAnalytic, PerRowSpacingSetsEachRowsGroundDistances) {
  HeightField east = makeSyntheticField("flat", 40, 9);
  for (int row = 0; row < east.height; ++row) {
    for (int c = 30; c < east.width; ++c) east.heights[row * east.width + c] += 10.0f;
    east.row_cell_size_x.push_back(2.0 + 0.5 * row);
    east.row_cell_size_y.push_back(3.0);
  }
  east.cell_size_x = east.row_cell_size_x[4];
  east.cell_size_y = 3.0;
  HorizonOutputs outputs;
  outputs.horizon_angles = outputs.horizon_distances = true;
  const auto r = run(east, 4, outputs);
  for (int row = 0; row < east.height; ++row) {
    for (int c = 0; c < 30; ++c) {
      const std::size_t p = row * east.width + c;
      const double d = (30 - c) * (2.0 + 0.5 * row);
      EXPECT_NEAR(r.angles[p], std::atan(10.0 / d), 1e-5) << c << "," << row;
      EXPECT_NEAR(r.distances[p], d, 1e-3 * d) << c << "," << row;
    }
  }
  // Within a maximum distance of 40 ground units only the rows' own distances decide whether the
  // wall is seen.
  {
    const double max_distance = 40.0;
    const auto w = run(east, 4, outputs, 0.0, max_distance);
    int seen = 0, unseen = 0;
    for (int row = 0; row < east.height; ++row) {
      for (int c = 0; c < 30; ++c) {
        const std::size_t p = row * east.width + c;
        const double d = (30 - c) * (2.0 + 0.5 * row);
        if (d < max_distance - 1e-3) {
          EXPECT_NEAR(w.angles[p], std::atan(10.0 / d), 1e-5) << c << "," << row;
          ++seen;
        } else if (d > max_distance + 1e-3) {
          EXPECT_NEAR(w.angles[p], 0.0, 1e-6) << c << "," << row;
          EXPECT_LE(w.distances[p], max_distance) << c << "," << row;
          ++unseen;
        }
      }
    }
    EXPECT_GT(seen, 20);
    EXPECT_GT(unseen, 20);
  }
  HeightField south = makeSyntheticField("flat", 9, 40);
  for (int row = 0; row < south.height; ++row) {
    if (row >= 30)
      for (int c = 0; c < south.width; ++c) south.heights[row * south.width + c] += 10.0f;
    south.row_cell_size_x.push_back(2.0);
    south.row_cell_size_y.push_back(1.0 + 0.05 * row);
  }
  south.cell_size_x = 2.0;
  south.cell_size_y = south.row_cell_size_y[20];
  const auto s = run(south, 4, outputs);
  const std::size_t plane = south.pixelCount();
  for (int row = 0; row < 30; ++row) {
    double d = 0.0;
    for (int j = row; j < 30; ++j) d += 1.0 + 0.05 * (j + 0.5);
    for (int c = 0; c < south.width; ++c) {
      const std::size_t p = plane + row * south.width + c;  // direction 1: +y
      EXPECT_NEAR(s.angles[p], std::atan(10.0 / d), 1e-5) << c << "," << row;
      // Next to the wall the slope at the receiver and the wall's top cast the same elevation,
      // and the summed ground lengths decide that tie either way (distance 0: the slope).
      if (row == 29 && s.distances[p] == 0.0f) continue;
      EXPECT_NEAR(s.distances[p], d, 1e-3 * d) << c << "," << row;
    }
  }
}

// Occlusion on a latitude / longitude-like grid: the top half's rows are 1 wide, the bottom
// half's 2 (its centre row, whose size the field carries, among them). The surface rises 0.5 per
// column, so in the top half it is a plane of slope 0.5 in ground units, which flattens beyond
// the kink: unoccluded, occlusion 1, only if the normals take each row's own spacing.
TEST_P(HorizonAnalytic, OcclusionNormalsTakeEachRowsSpacing) {
  HeightField field = makeSyntheticField("flat", 33, 80);
  for (int row = 0; row < field.height; ++row) {
    for (int c = 0; c < field.width; ++c) field.heights[row * field.width + c] = 0.5f * c;
    field.row_cell_size_x.push_back(row < 40 ? 1.0 : 2.0);
    field.row_cell_size_y.push_back(1.0);
  }
  field.cell_size_x = field.row_cell_size_x[40];
  field.cell_size_y = 1.0;
  HorizonOutputs outputs;
  outputs.ambient_occlusion = true;
  const auto r = run(field, 64, outputs);
  for (int row = 4; row < 36; ++row) {
    for (int c = 4; c < 20; ++c) {  // far enough from the uphill edge for every ray to meet samples
      EXPECT_NEAR(r.ambient_occlusion[row * field.width + c], 1.0, 2e-3) << c << "," << row;
    }
  }
}

// The same wall over a curved Earth (drop c d^2 at ground distance d): its top is seen at
// atan((z * 10 - c d^2) / d), d = cell_x * (30 - c), still from the foot of its top (the
// farther wall lies lower still). c is large enough to halve the nearest elevations. Right in
// front of the wall (column 29) the sweep's horizon is the ramp's own slope at the receiver,
// its limit at t -> 0 (the drop is of second order there), at distance 0; the naive march
// samples the wall's top.
TEST_P(HorizonAnalytic, LongWallOverACurvedEarthSinksByTheDrop) {
  HeightField field = makeSyntheticField("flat", 40, 9);
  for (int row = 0; row < field.height; ++row)
    for (int c = 30; c < field.width; ++c) field.heights[row * field.width + c] += 10.0f;
  field.cell_size_x = 2.0;
  field.z_scale = 3.0;
  const double curvature = 0.005;
  HorizonOutputs outputs;
  outputs.horizon_angles = outputs.horizon_distances = true;
  const auto r = run(field, 4, outputs, curvature);
  for (int row = 0; row < field.height; ++row) {
    for (int c = 0; c < 30; ++c) {
      const std::size_t p = row * field.width + c;
      const double d = 2.0 * (30 - c);
      const bool ramp = c == 29 && GetParam() == HorizonMethod::Sweep;
      EXPECT_NEAR(r.angles[p], std::atan(ramp ? 30.0 / d : (30.0 - curvature * d * d) / d), 1e-5) << c << "," << row;
      EXPECT_NEAR(r.distances[p], ramp ? 0.0 : d, 1e-3) << c << "," << row;
    }
  }
}

// Flat ground over a curved Earth falls away from every receiver: the horizon is level (the
// ground's own slope at the receiver) for the sweep, and the nearest sample's drop below the
// receiver, -atan(c step) at a step of 1 ground unit, for the naive march.
TEST_P(HorizonAnalytic, FlatGroundOverACurvedEarthFallsAway) {
  const HeightField field = makeSyntheticField("flat", 19, 14);
  const double curvature = 0.01;
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  const auto r = run(field, 4, outputs, curvature);
  const double expected = GetParam() == HorizonMethod::Sweep ? 0.0 : -std::atan(curvature);
  for (int row = 1; row < field.height - 1; ++row)
    for (int c = 1; c < field.width - 1; ++c)
      for (int k = 0; k < 4; ++k)
        ASSERT_NEAR(r.angles[k * field.pixelCount() + row * field.width + c], expected, 1e-6) << k;
}

// A cone of slope 0.5 around (20, 20): along its row every receiver looks up the cone's
// straight flank to the apex.
TEST_P(HorizonAnalytic, ConeFlankSeesTheApexAtTheConeSlope) {
  HeightField field = makeSyntheticField("flat", 41, 41);
  for (int row = 0; row < 41; ++row)
    for (int c = 0; c < 41; ++c)
      field.heights[row * 41 + c] = float(20.0 - 0.5 * std::hypot(c - 20.0, row - 20.0));
  HorizonOutputs outputs;
  outputs.horizon_angles = outputs.horizon_distances = true;
  const auto r = run(field, 4, outputs);
  const std::size_t plane = field.pixelCount();
  for (int c = 0; c < 20; ++c) {
    EXPECT_NEAR(r.angles[0 * plane + 20 * 41 + c], std::atan(0.5), 1e-5) << c;  // toward +x
    EXPECT_NEAR(r.distances[0 * plane + 20 * 41 + c], 20.0 - c, 1e-3) << c;
    EXPECT_NEAR(r.angles[1 * plane + c * 41 + 20], std::atan(0.5), 1e-5) << c;  // toward +y
  }
}

// A tilted plane h = a x sees the whole hemisphere around its normal: ambient occlusion 1
// up to the swath discretisation of Eq. 5, and sky-view factor
// 1 - mean over uphill directions of sin(atan(a cos phi)).
TEST_P(HorizonAnalytic, TiltedPlaneOcclusionAndSkyView) {
  const double a = 0.5;
  HeightField field = makeSyntheticField("flat", 33, 33);
  for (int row = 0; row < 33; ++row)
    for (int c = 0; c < 33; ++c) field.heights[row * 33 + c] = float(a * c);
  const int K = 64;
  const auto r = run(field, K, everything());
  double svf = 0.0;
  for (int k = 0; k < K; ++k) svf += std::sin(std::max(0.0, std::atan(a * std::cos(2 * M_PI * k / K))));
  svf = 1.0 - svf / K;
  for (int row = 4; row < 29; ++row) {
    for (int c = 4; c < 20; ++c) {  // far enough from the uphill edge for every ray to meet samples
      const std::size_t p = row * 33 + c;
      EXPECT_NEAR(r.ambient_occlusion[p], 1.0, 2e-3) << c << "," << row;
      EXPECT_NEAR(r.sky_view_factor[p], svf, 5e-3) << c << "," << row;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, HorizonAnalytic,
                         ::testing::Values(HorizonMethod::Sweep, HorizonMethod::Naive), [](const auto& info) {
                           return info.param == HorizonMethod::Sweep ? "Sweep" : "Naive";
                         });

}  // namespace
}  // namespace hfvis

namespace hfvis {
namespace {

// Grid accuracy, a loose regression bound (the benchmark reports the figures): on a crop of
// the bundled fractal terrain, against a dense naive march (16 samples per pixel), the
// sweep's receiver-exact horizons are more accurate than the unit-step naive march, and
// denser sampling along the lines makes them more accurate still.
TEST(HorizonAccuracy, SweepBeatsTheUnitMarchAndImprovesWithSampling) {
  const HeightField whole = readHeightField(std::string(HFVIS_DATA_DIR) + "/fractal_256.exr");
  const int size = 96, origin = 80;
  HeightField field = testing::fieldFrom(size, size, {});
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c) field.heights.push_back(whole.at(origin + c, origin + r));
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  // K = 8: the sweep's steps (the axes and diagonals) lie exactly at phi_k, as the truth's.
  auto horizons = [&](HorizonMethod method, double samples_per_unit) {
    HorizonOptions options;
    options.directions = 8;
    options.method = method;
    options.samples_per_unit = samples_per_unit;
    return computeHorizons(testing::testContext(), field, options, outputs);
  };
  const auto truth = horizons(HorizonMethod::Naive, 16);
  auto meanErrorDegrees = [&](const HorizonResult& result) {
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < 8; ++k)
      for (int r = 2; r < size - 2; ++r)
        for (int c = 2; c < size - 2; ++c) {
          const std::size_t i = k * field.pixelCount() + r * size + c;
          sum += std::abs(result.angles[i] - truth.angles[i]), ++count;
        }
    return sum / count * 180.0 / M_PI;
  };
  const double naive = meanErrorDegrees(horizons(HorizonMethod::Naive, 1));
  const double sweep = meanErrorDegrees(horizons(HorizonMethod::Sweep, 1));
  const double sweep_dense = meanErrorDegrees(horizons(HorizonMethod::Sweep, 4));
  RecordProperty("mean_error_deg_naive", std::to_string(naive));
  RecordProperty("mean_error_deg_sweep", std::to_string(sweep));
  RecordProperty("mean_error_deg_sweep_spu4", std::to_string(sweep_dense));
  EXPECT_LT(sweep, 0.5 * naive);
  EXPECT_LT(sweep_dense, sweep);
}

// Two flat roofs of height H that touch only at a corner, seen diagonally from the ground: along
// the diagonal through the shared corner's cell, whose two high corners lie off the line, the
// bilinear surface is 2 H u (1 - u), peaking at H / 2 inside the cell, where no grid crossing
// is (the crossings along a diagonal are grid points, all on the ground). The sweep takes that
// peak: from the receiver 2.5 cell diagonals away its horizon is atan((H / 2) / (2.5 sqrt 2)),
// just under the exact tangent (u = sqrt 6 - 2 instead of 1/2: 55.0 deg against 54.7 for
// H = 10); the crossings alone give 0 and the unit march about 35 deg.
TEST(HorizonAccuracy, RoofsTouchingAtACornerCastTheirPeakAlongTheDiagonal) {
  const int n = 9;
  const float H = 10.0f;
  std::vector<float> heights(n * n, 0.0f);
  for (int r = 0; r <= 3; ++r)
    for (int c = 4; c < n; ++c) heights[r * n + c] = H;  // one roof: columns 4.., rows ..3
  for (int r = 4; r < n; ++r)
    for (int c = 0; c <= 3; ++c) heights[r * n + c] = H;  // the other: columns ..3, rows 4..
  const HeightField field = testing::fieldFrom(n, n, heights);
  HorizonOptions options;
  options.directions = 8;  // direction 1 is the diagonal (1, 1)
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  const std::size_t at = field.pixelCount() + 1 * n + 1;  // direction 1 at (1, 1)
  const HorizonResult sweep = computeHorizons(testing::testContext(), field, options, outputs);
  const double peak = std::atan((H / 2.0) / (2.5 * std::sqrt(2.0)));
  const double u = std::sqrt(6.0) - 2.0, exact = std::atan(2.0 * H * u * (1.0 - u) / ((2.0 + u) * std::sqrt(2.0)));
  EXPECT_NEAR(sweep.angles[at], peak, 1e-5);
  EXPECT_LT(sweep.angles[at], exact);
  EXPECT_NEAR(referenceHorizons(field, options, outputs).angles[at], peak, 1e-5);
  options.method = HorizonMethod::Naive;
  const HorizonResult naive = computeHorizons(testing::testContext(), field, options, outputs);
  EXPECT_LT(naive.angles[at], peak - 0.2);  // the unit march's samples miss the peak
}

// The same on a whole city DSM (the city hard case: one-pixel streets and walls, roofs that
// touch at corners, a rotated street grid), against a dense naive march (16 samples per pixel)
// at the same azimuths: the default sweep's mean horizon error is at most half the unit naive
// march's and its 99th percentile no larger; denser sampling does not make it worse.
TEST(HorizonAccuracy, SweepBeatsTheUnitMarchOnACity) {
  const int size = 96;
  const HeightField field = makeSyntheticField("city", size, size, 1);
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  const int K = 16;
  auto horizons = [&](HorizonMethod method, double samples_per_unit) {
    HorizonOptions options;
    options.directions = K;
    options.method = method;
    options.samples_per_unit = samples_per_unit;
    return computeHorizons(testing::testContext(), field, options, outputs);
  };
  const auto truth = horizons(HorizonMethod::Naive, 16);
  struct Errors {
    double mean, p99;
  };
  auto errorsDegrees = [&](const HorizonResult& result) {
    std::vector<double> e;
    for (int k = 0; k < K; ++k)
      for (int r = 2; r < size - 2; ++r)
        for (int c = 2; c < size - 2; ++c) {
          const std::size_t i = k * field.pixelCount() + r * size + c;
          e.push_back(std::abs(result.angles[i] - truth.angles[i]) * 180.0 / M_PI);
        }
    std::sort(e.begin(), e.end());
    double sum = 0.0;
    for (double v : e) sum += v;
    return Errors{sum / e.size(), e[static_cast<std::size_t>(0.99 * (e.size() - 1))]};
  };
  const Errors naive = errorsDegrees(horizons(HorizonMethod::Naive, 1));
  const Errors sweep = errorsDegrees(horizons(HorizonMethod::Sweep, 1));
  const Errors sweep_dense = errorsDegrees(horizons(HorizonMethod::Sweep, 4));
  std::printf("city %dx%d, K = %d, against a 1/16-pixel march: mean / p99 error naive %.3f / %.2f, sweep %.3f / %.2f, "
              "sweep S = 4 %.3f / %.2f deg\n", size, size, K, naive.mean, naive.p99, sweep.mean, sweep.p99,
              sweep_dense.mean, sweep_dense.p99);
  EXPECT_LT(sweep.mean, 0.5 * naive.mean);
  EXPECT_LE(sweep.p99, naive.p99);
  EXPECT_LE(sweep_dense.mean, sweep.mean * 1.05);
}

// On a dome (a concave surface; its bilinear interpolation is piecewise linear along any
// ray, since the cross term of x^2 + y^2 vanishes) no chord from a receiver is steeper than
// the surface at the receiver, so the horizon is the limit at t -> 0, the sweep's exact
// near limit, also for steps off the axes. The first cell is linear along the ray, so the
// first crossing ties with that limit: the horizon point lies within the first cell.
TEST(HorizonAccuracy, DomeHorizonIsTheSlopeAtTheReceiver) {
  const int n = 31;
  HeightField field = testing::fieldFrom(n, n, {});
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      field.heights.push_back(-0.02f * float((c - 15) * (c - 15) + (r - 15) * (r - 15)));
  field.cell_size_x = 1.5;
  HorizonOptions options;
  options.directions = 16;
  HorizonOutputs outputs;
  outputs.horizon_angles = outputs.horizon_distances = true;
  const auto result = computeHorizons(testContext(), field, options, outputs);
  int off_axis = 0;
  for (int k = 0; k < 16; ++k) {
    const auto d = detail::latticeDirections(field, options, true, options.azimuth_tolerance)[k];
    off_axis += d.a != 0 && d.b != 0;
    const int sx = (d.a > 0) - (d.a < 0), sy = (d.b > 0) - (d.b < 0);
    for (int r = 1; r < n - 1; ++r) {
      for (int c = 1; c < n - 1; ++c) {
        const std::size_t i = k * field.pixelCount() + r * n + c;
        const double h = field.at(c, r);
        const double rise =
            (field.at(c + sx, r) - h) * std::abs(d.a) + (field.at(c, r + sy) - h) * std::abs(d.b);
        const double expected = std::atan(rise / (d.period * d.ground_per_pixel));
        ASSERT_NEAR(result.angles[i], expected, 2e-6) << "k " << k << " pixel " << c << "," << r;
        const double first_crossing =
            (d.a != 0 && d.b != 0 ? 1.0 / std::max(std::abs(d.a), std::abs(d.b)) : 1.0) * d.period *
            d.ground_per_pixel;
        ASSERT_LE(result.distances[i], first_crossing * (1 + 1e-6))
            << "k " << k << " pixel " << c << "," << r;
      }
    }
  }
  EXPECT_GE(off_axis, 8);
}

}  // namespace
}  // namespace hfvis
