// test_fast_math.cpp: accuracy of the polynomial atan/sin that the reductions use
// (kernels/shared/fast_math.cl, mirrored by src/core/fast_math.hpp), against the C library in double.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/fast_math.hpp"

namespace hfvis::detail {
namespace {

TEST(FastMath, AtanWithinTwoTenthsOfAMicroradian) {
  double worst = 0.0;
  for (int i = -200000; i <= 200000; ++i) {
    // Dense near 0, then growing to 1e6 in magnitude: sinh spreads the samples.
    const float x = static_cast<float>(std::sinh(i * 1e-4));
    worst = std::max(worst, std::abs(double(hfAtan(x)) - std::atan(double(x))));
  }
  EXPECT_LT(worst, 2e-7);
  EXPECT_FLOAT_EQ(hfAtan(std::numeric_limits<float>::infinity()), kPiF / 2);
  EXPECT_FLOAT_EQ(hfAtan(-std::numeric_limits<float>::infinity()), -kPiF / 2);
  EXPECT_EQ(hfAtan(0.0f), 0.0f);
  EXPECT_TRUE(std::isnan(hfAtan(std::numeric_limits<float>::quiet_NaN())));
}

// The horizon kernels take an elevation as hf_atan(rise / run), run > 0.
TEST(FastMath, AtanOfAQuotientMatchesAtan2ForPositiveX) {
  double worst = 0.0;
  for (float y : {-1e6f, -3.0f, -1e-3f, 0.0f, 2e-5f, 0.7f, 1.0f, 40.0f, 1e6f})
    for (float x : {1e-3f, 0.5f, 1.0f, 7.0f, 1e4f})
      worst = std::max(worst, std::abs(double(hfAtan(y / x)) - std::atan2(double(y), double(x))));
  EXPECT_LT(worst, 2e-7);
}

TEST(FastMath, SinWithinATenthOfAMicroOnTwoTurns) {
  double worst = 0.0;
  for (int i = -100000; i <= 100000; ++i) {
    const float x = static_cast<float>(i * (2 * M_PI / 100000));
    worst = std::max(worst, std::abs(double(hfSin(x)) - std::sin(double(x))));
  }
  EXPECT_LT(worst, 1e-7 + 1e-7);  // the polynomial's 6e-8 plus float rounding of x
}

}  // namespace
}  // namespace hfvis::detail
