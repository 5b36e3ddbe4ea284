// tanh_through_exp against std::tanh: the valve law's K_p(e) and direction compensation use it in
// place of std::tanh, so it must be the same odd, saturating, increasing function to within a
// rounding error of the result's magnitude.
#include "control/tanh_through_exp.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace hsa::control {
namespace {

TEST(TanhThroughExp, IsStdTanhToWithinRoundingEverywhere) {
  double worst = 0.0;
  // A dense grid over where tanh bends, and a logarithmic one from the tiny to the saturated.
  for (int i = -400000; i <= 400000; ++i) {
    const double y = i * 2.5e-5;
    worst = std::fmax(worst, std::fabs(tanh_through_exp(y) - std::tanh(y)));
  }
  for (double y = 1e-300; y < 1e3; y *= 1.07) {
    worst = std::fmax(worst, std::fabs(tanh_through_exp(y) - std::tanh(y)));
    worst = std::fmax(worst, std::fabs(tanh_through_exp(-y) - std::tanh(-y)));
  }
  EXPECT_LE(worst, 2.3e-16);
}

TEST(TanhThroughExp, IsOddAndNonDecreasing) {
  double last = -1.0;
  for (int i = -200000; i <= 200000; ++i) {
    const double y = i * 1e-4;
    const double t = tanh_through_exp(y);
    ASSERT_EQ(t, -tanh_through_exp(-y)) << y;
    ASSERT_GE(t, last) << y;
    last = t;
  }
}

TEST(TanhThroughExp, SaturatesAndPassesNaN) {
  EXPECT_EQ(tanh_through_exp(0.0), 0.0);
  EXPECT_EQ(tanh_through_exp(30.0), 1.0);
  EXPECT_EQ(tanh_through_exp(-30.0), -1.0);
  EXPECT_EQ(tanh_through_exp(std::numeric_limits<double>::infinity()), 1.0);
  EXPECT_EQ(tanh_through_exp(-std::numeric_limits<double>::infinity()), -1.0);
  EXPECT_TRUE(std::isnan(tanh_through_exp(std::numeric_limits<double>::quiet_NaN())));
}

}  // namespace
}  // namespace hsa::control
