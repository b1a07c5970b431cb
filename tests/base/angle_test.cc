#include "base/angle.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace vtrack {
namespace {

// Reference: atan2(sin a, cos a) lies in (-pi, pi] by definition of atan2.
TEST(Angle, WrapMatchesAtan2Reference) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  for (int i = 0; i < 10000; ++i) {
    const double a = u(rng);
    EXPECT_NEAR(WrapToPi(a), std::atan2(std::sin(a), std::cos(a)), 1e-9) << a;
  }
}

TEST(Angle, WrapRangeIsHalfOpenAtMinusPi) {
  EXPECT_DOUBLE_EQ(WrapToPi(kPi), kPi);
  EXPECT_DOUBLE_EQ(WrapToPi(-kPi), kPi);
  EXPECT_DOUBLE_EQ(WrapToPi(3 * kPi), kPi);
  EXPECT_DOUBLE_EQ(WrapToPi(0.0), 0.0);
  EXPECT_NEAR(AngleDiff(kPi - 0.1, -kPi + 0.1), -0.2, 1e-12);
  EXPECT_NEAR(AngleDiff(-kPi + 0.1, kPi - 0.1), 0.2, 1e-12);
}

}  // namespace
}  // namespace vtrack
