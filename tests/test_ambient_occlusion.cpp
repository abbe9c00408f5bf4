// test_ambient_occlusion.cpp: ambient occlusion (hfvis/ambient_occlusion.hpp): the kernels
// against the scalar reference on every hard case in both buffer layouts, the same values as the
// horizon operation's output, and closed forms (a street canyon, a tilted plane).
#include <gtest/gtest.h>

#include <cmath>

#include "hfvis/ambient_occlusion.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis_testing/ambient_occlusion_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::nearlyEqual;
using testing::testContext;

HorizonOptions optionsFor(HorizonMethod method, int directions) {
  HorizonOptions options;
  options.method = method;
  options.directions = directions;
  return options;
}

TEST(AmbientOcclusion, KernelsMatchTheScalarReferenceOnEveryHardCase) {
  testing::forEachLayout([](const ComputeContext& context) {
    for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
      HorizonOptions options = optionsFor(method, 7);
      options.azimuth_offset = 0.1;
      testing::forEachHardCase([&](const std::string&, const HeightField& field) {
        const auto device = computeAmbientOcclusion(context, field, options);
        const auto reference = referenceAmbientOcclusion(field, options);
        ASSERT_EQ(device.width, field.width);
        ASSERT_EQ(device.height, field.height);
        EXPECT_TRUE(nearlyEqual(device.values, reference.values, testing::divisionTolerance()));
      });
    }
  });
}

// The operation is the horizon sweep with this output alone: the same values, bit for bit.
TEST(AmbientOcclusion, EqualsTheHorizonOperationsOutput) {
  const HeightField field = makeSyntheticField("city", 40, 41);
  HorizonOutputs outputs;
  outputs.ambient_occlusion = true;
  const HorizonOptions options = optionsFor(HorizonMethod::Sweep, 16);
  EXPECT_TRUE(nearlyEqual(computeAmbientOcclusion(testContext(), field, options).values,
                          computeHorizons(testContext(), field, options, outputs).ambient_occlusion, 0.0f));
}

// On level ground (normal up) each swath of weight w under a horizon of elevation e brings
// w cos^2(e) (Eq. 5). In the street canyon of test_sky_view_factor.cpp (walls 3 pixels away, 4
// deep): cos^2 = 9 / 25 across the street, 18 / 34 along the diagonals, 1 along the street. K = 4:
// AO = (2 (9 / 25) + 2) / 4 = 0.68, both methods; K = 8, the sweep: (2 (9 / 25) + 4 (18 / 34) + 2) / 8.
TEST(AmbientOcclusion, StreetCanyonHasTheClosedFormValue) {
  const HeightField field = testing::streetCanyon(41, 61, 3, 4.0f);
  struct Case {
    HorizonMethod method;
    int directions;
    double expected;
  };
  for (const Case& c : {Case{HorizonMethod::Sweep, 4, 0.68}, Case{HorizonMethod::Naive, 4, 0.68},
                        Case{HorizonMethod::Sweep, 8, (2 * 0.36 + 4 * 18.0 / 34.0 + 2) / 8}}) {
    SCOPED_TRACE("K = " + std::to_string(c.directions) + (c.method == HorizonMethod::Naive ? " naive" : " sweep"));
    const auto r = computeAmbientOcclusion(testContext(), field, optionsFor(c.method, c.directions));
    for (int row = 20; row <= 40; ++row) EXPECT_NEAR(r.values[row * field.width + 20], c.expected, 1e-5) << row;
  }
}

// A tilted plane with nothing above its tangent plane receives the whole sky its normal faces:
// 1, up to the swaths' discretisation of Eq. 5 (unlike the sky-view factor, which counts the
// sky the plane hides).
TEST(AmbientOcclusion, TiltedPlaneIsUnoccluded) {
  HeightField field = makeSyntheticField("flat", 33, 33);
  for (int row = 0; row < 33; ++row)
    for (int c = 0; c < 33; ++c) field.heights[row * 33 + c] = float(0.5 * c);
  for (HorizonMethod method : {HorizonMethod::Sweep, HorizonMethod::Naive}) {
    const auto r = computeAmbientOcclusion(testContext(), field, optionsFor(method, 64));
    for (int row = 4; row < 29; ++row)
      for (int c = 4; c < 20; ++c) EXPECT_NEAR(r.values[row * 33 + c], 1.0, 2e-3) << c << "," << row;
  }
}

}  // namespace
}  // namespace hfvis
