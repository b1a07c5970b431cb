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

// An angle already in (-pi, pi] comes back unchanged, bit for bit, as std::remainder would give
// it: the short cut for in-range angles changes no result. Across the edges too (next doubles).
TEST(Angle, WrapIsTheRemainderBitForBit) {
  const auto reference = [](double a) {
    double r = std::remainder(a, 2.0 * kPi);
    return r <= -kPi ? r + 2.0 * kPi : r;
  };
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-4.0 * kPi, 4.0 * kPi);
  for (int i = 0; i < 100000; ++i) {
    const double a = u(rng);
    EXPECT_EQ(WrapToPi(a), reference(a)) << a;
  }
  for (const double edge : {kPi, -kPi, 0.0}) {
    for (const double a : {std::nextafter(edge, -10.0), edge, std::nextafter(edge, 10.0)}) {
      EXPECT_EQ(WrapToPi(a), reference(a)) << a;
    }
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
