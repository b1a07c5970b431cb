// Atan2Approx against std::atan2 (the independent reference): its stated error bound over
// seeded random directions at ranges from millimetres to kilometres, the octant boundaries and
// the axes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "tracker/core/fast_atan2.h"

namespace vtrack {
namespace {

TEST(Atan2ApproxTest, WithinBoundOfStdAtan2OverRandomDirections) {
  std::mt19937_64 rng(20261122);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  std::uniform_real_distribution<double> log_range(-3.0, 3.0);
  double worst = 0.0;
  for (int k = 0; k < 1000000; ++k) {
    const double r = std::pow(10.0, log_range(rng));
    const double a = angle(rng);
    const double x = r * std::cos(a), y = r * std::sin(a);
    worst = std::max(worst, std::abs(Atan2Approx(y, x) - std::atan2(y, x)));
  }
  EXPECT_LT(worst, kAtan2ApproxMaxError);
  // The bound is not loose by orders of magnitude either way: the series' truncation shows.
  EXPECT_GT(worst, 1e-16);
}

// Two at a time (the range profile's loop): each lane within the bound of std::atan2 and exactly
// the value of its own inputs one at a time, whatever the other lane holds (a lane's select must
// not take the other's condition), over random pairs mixed with the axes, the diagonals
// (|x| = |y|), the reduction threshold, zeros and NaN.
TEST(Atan2ApproxTest, TwoLanesGiveEachItsOwnValue) {
  std::mt19937_64 rng(20261201);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  std::uniform_real_distribution<double> log_range(-3.0, 3.0);
  const double t12 = 2.0 - std::sqrt(3.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::pair<double, double>> special = {
      {0.0, 1.0}, {1.0, 0.0}, {0.0, -1.0}, {-1.0, 0.0}, {0.0, 0.0}, {2.5, 2.5}, {-2.5, 2.5},
      {2.5, -2.5}, {-2.5, -2.5}, {t12, 1.0}, {-1.0, -t12}, {nan, 1.0}, {1.0, nan}};
  int checked = 0;
  for (int k = 0; k < 200000; ++k) {
    std::pair<double, double> in[2];
    for (auto& p : in) {
      if (k % 7 == 0) {
        p = special[static_cast<std::size_t>(rng() % special.size())];
      } else {
        const double r = std::pow(10.0, log_range(rng)), a = angle(rng);
        p = {r * std::sin(a), r * std::cos(a)};
      }
    }
    const Double2 v = Atan2Approx2(Double2{in[0].first, in[1].first}, Double2{in[0].second, in[1].second});
    for (int lane = 0; lane < 2; ++lane) {
      const auto [y, x] = in[lane];
      const double one = Atan2Approx(y, x);
      if (std::isnan(one)) {
        EXPECT_TRUE(std::isnan(v[lane])) << "y " << y << " x " << x;
      } else {
        EXPECT_EQ(v[lane], one) << "lane " << lane << " y " << y << " x " << x;
      }
      if (std::isfinite(y) && std::isfinite(x) && (x != 0.0 || y != 0.0)) {
        EXPECT_NEAR(v[lane], std::atan2(y, x), kAtan2ApproxMaxError) << "y " << y << " x " << x;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 300000);
}

TEST(Atan2ApproxTest, ExactStructureAtAxesAndOctantBoundaries) {
  for (const double r : {1e-3, 1.0, 37.5, 1e4}) {
    for (int k = -8; k <= 8; ++k) {
      // Multiples of pi/8: the axes, the diagonals (t = 1) and points in between.
      const double a = k * M_PI / 8.0;
      const double x = r * std::cos(a), y = r * std::sin(a);
      EXPECT_NEAR(Atan2Approx(y, x), std::atan2(y, x), kAtan2ApproxMaxError)
          << "r " << r << " angle " << a;
    }
    // t exactly at the reduction threshold tan(pi/12) and just either side of it.
    const double t12 = 2.0 - std::sqrt(3.0);
    for (const double t : {std::nextafter(t12, 0.0), t12, std::nextafter(t12, 1.0)}) {
      EXPECT_NEAR(Atan2Approx(r * t, r), std::atan2(r * t, r), kAtan2ApproxMaxError);
      EXPECT_NEAR(Atan2Approx(-r, -r * t), std::atan2(-r, -r * t), kAtan2ApproxMaxError);
    }
  }
  EXPECT_DOUBLE_EQ(Atan2Approx(0.0, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(Atan2Approx(1.0, 0.0), 0.5 * M_PI);
  EXPECT_DOUBLE_EQ(Atan2Approx(0.0, -1.0), M_PI);
  EXPECT_DOUBLE_EQ(Atan2Approx(-1.0, 0.0), -0.5 * M_PI);
  EXPECT_EQ(Atan2Approx(0.0, 0.0), 0.0);
}

}  // namespace
}  // namespace vtrack
