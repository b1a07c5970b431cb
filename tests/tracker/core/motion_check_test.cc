// ReturnsMovedWith (classification.h): a scan is evidence of motion only if the track's returns
// moved with its estimated velocity. The truth is the scene: the corner of a car sampled with
// seeded range noise, once where it was and once where it went.
#include "tracker/core/classification.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

namespace vtrack {
namespace {

constexpr double kNoise = 0.02;  // [m] std of each return's position, per axis

// The rear face (1.8 m) and the right side (first `side` metres) of a car whose rear right
// corner is at `corner` (world), heading +x, sampled every 0.1 m from `phase` on, with seeded
// noise; the returns relative to `origin`.
PointSet Corner(const Eigen::Vector2d& corner, double side, double phase,
                const Eigen::Vector2d& origin, std::uint32_t seed, std::int64_t utime,
                bool rear = true) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kNoise);
  PointSet p;
  p.origin = origin;
  auto add = [&](double x, double y) {
    p.x.push_back(static_cast<float>(x + noise(rng) - origin.x()));
    p.y.push_back(static_cast<float>(y + noise(rng) - origin.y()));
  };
  if (rear) {
    for (double s = phase; s <= 1.8; s += 0.1) add(corner.x(), corner.y() + s);
  }
  for (double s = phase; s <= side; s += 0.1) add(corner.x() + s, corner.y());
  p.mean_utime = utime;
  return p;
}

ReturnsSnapshot SnapshotOf(const PointSet& p) {
  ReturnsSnapshot s;
  SnapshotReturns(p, &s);
  return s;
}

TEST(ReturnsMovedWith, AMovingCarsReturnsMovedWithItsDisplacement) {
  const Eigen::Vector2d corner(30.0, 4.0), d(0.9, 0.3);  // 9.5 m/s over 0.1 s
  // Different frames, samplings and noise on the two scans.
  const PointSet before = Corner(corner, 4.5, 0.0, {29.0, 3.0}, 1, 0);
  const PointSet now = Corner(corner + d, 4.5, 0.05, {31.0, 5.0}, 2, 100'000);
  EXPECT_TRUE(ReturnsMovedWith(now, SnapshotOf(before), d));
  // Claimed the other way, or across, they did not.
  EXPECT_FALSE(ReturnsMovedWith(now, SnapshotOf(before), -d));
  EXPECT_FALSE(ReturnsMovedWith(now, SnapshotOf(before), Eigen::Vector2d(-d.y(), d.x())));
}

TEST(ReturnsMovedWith, AParkedCarComingIntoViewDidNotMove) {
  // The ego drives past: 1.5 m more of the side is seen, so the centre of the seen part moves
  // 0.75 m along the car and a filter takes it up as velocity; the returns stay where they were.
  const Eigen::Vector2d corner(30.0, 4.0);
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const PointSet before = Corner(corner, 2.0, 0.0, {30.0, 4.0}, seed, 0);
    const PointSet now = Corner(corner, 3.5, 0.05, {30.5, 4.0}, 100 + seed, 100'000);
    const ReturnsSnapshot snap = SnapshotOf(before);
    for (const Eigen::Vector2d& d : {Eigen::Vector2d(0.3, 0.0), Eigen::Vector2d(0.0, 0.3),
                                    Eigen::Vector2d(0.2, 0.2), Eigen::Vector2d(0.75, 0.0)}) {
      EXPECT_FALSE(ReturnsMovedWith(now, snap, d)) << "seed " << seed << ", d " << d.transpose();
    }
  }
}

TEST(ReturnsMovedWith, ASideComingFurtherIntoViewDidNotMoveAcrossItself) {
  // Only the side is seen, and 1.5 m more of it on the second scan. Along a single face only the
  // displacement across it is observable (the tracker tests that component alone, as the mover
  // test does); across it the returns did not move.
  const Eigen::Vector2d corner(30.0, 4.0);
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    const PointSet before = Corner(corner, 2.0, 0.0, {30.0, 4.0}, seed, 0, /*rear=*/false);
    const PointSet now = Corner(corner, 3.5, 0.05, {30.5, 4.0}, 100 + seed, 100'000, false);
    const ReturnsSnapshot snap = SnapshotOf(before);
    for (const Eigen::Vector2d& d : {Eigen::Vector2d(0.0, 0.3), Eigen::Vector2d(0.0, -0.3),
                                     Eigen::Vector2d(0.0, 0.1)}) {
      EXPECT_FALSE(ReturnsMovedWith(now, snap, d)) << "seed " << seed << ", d " << d.transpose();
    }
    // Moved across by 0.3 m, it did.
    const PointSet moved = Corner(corner + Eigen::Vector2d(0.0, 0.3), 3.5, 0.05, {30.5, 4.0},
                                  200 + seed, 100'000, false);
    EXPECT_TRUE(ReturnsMovedWith(moved, snap, Eigen::Vector2d(0.0, 0.3))) << "seed " << seed;
  }
}

TEST(ReturnsMovedWith, AWindowSlidingAlongAWallPasses) {
  // The aperture problem (classification.h): a straight wall seen from x = 0-8 m, then 1-9 m, with
  // the displacement claimed along it. Nothing in the returns tells it from no motion but the
  // ends, and those favour the displacement.
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, kNoise);
  auto wall = [&](double x0, std::int64_t utime) {
    PointSet p;
    for (double x = x0; x <= x0 + 8.0 + 1e-9; x += 0.1) {
      p.x.push_back(static_cast<float>(x + noise(rng)));
      p.y.push_back(static_cast<float>(5.0 + noise(rng)));
    }
    p.mean_utime = utime;
    return p;
  };
  const PointSet before = wall(0.0, 0), now = wall(1.0, 100'000);
  EXPECT_TRUE(ReturnsMovedWith(now, SnapshotOf(before), Eigen::Vector2d(1.0, 0.0)));
}

TEST(ReturnsMovedWith, NoDisplacementIsNoEvidence) {
  const PointSet before = Corner({30.0, 4.0}, 4.5, 0.0, {0.0, 0.0}, 3, 0);
  const PointSet now = Corner({30.0, 4.0}, 4.5, 0.0, {0.0, 0.0}, 4, 100'000);
  EXPECT_FALSE(ReturnsMovedWith(now, SnapshotOf(before), Eigen::Vector2d::Zero()));
}

TEST(ReturnsMovedWith, SnapshotKeepsAtMostTheCheckedReturnsEvenlyStrided) {
  PointSet p;
  p.origin = Eigen::Vector2d(12.0, -3.0);
  p.mean_utime = 42;
  for (int i = 0; i < 1000; ++i) {
    p.x.push_back(0.01f * static_cast<float>(i));
    p.y.push_back(-0.02f * static_cast<float>(i));
  }
  const ReturnsSnapshot s = SnapshotOf(p);
  ASSERT_LE(s.x.size(), kMotionCheckPoints);
  ASSERT_GE(s.x.size(), kMotionCheckPoints - 1);  // 1000 returns at a stride of 16: 63
  EXPECT_EQ(s.origin, p.origin);
  EXPECT_EQ(s.utime, 42);
  EXPECT_FLOAT_EQ(s.x.front(), 0.0f);
  // Evenly strided: the kept returns span the whole set.
  EXPECT_GT(s.x.back(), 0.01f * 900.0f);
  // A set no larger than the cap is kept whole.
  p.x.resize(10);
  p.y.resize(10);
  EXPECT_EQ(SnapshotOf(p).x.size(), 10u);
}

}  // namespace
}  // namespace vtrack
