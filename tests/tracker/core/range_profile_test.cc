// RangeProfile (track_manager.h): whether a fitted face is seen whole, checked against scenes
// built by hand whose answer follows from the geometry: a face ends in free space, behind a low
// object near the sensor that only the downward rings hit, behind a real occluder on the face's
// rings, or continues at the same range.
#include "tracker/core/range_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "base/angle.h"

namespace vtrack {
namespace {

constexpr double kBinDeg = 0.2;
constexpr double kMargin = 0.5;  // [m] as AlignToFullFace uses it
constexpr int kBins = 3;

struct Cloud {
  std::vector<double> x, y;
  std::vector<std::int16_t> ring;
  void Add(double px, double py, int r) {
    x.push_back(px);
    y.push_back(py);
    ring.push_back(static_cast<std::int16_t>(r));
  }
  // A face across the ray at range `at` from y0 to y1, hit by rings r0..r1, every 2 cm.
  void Face(double at, double y0, double y1, int r0, int r1) {
    for (int r = r0; r <= r1; ++r) {
      for (double v = y0; v <= y1 + 1e-9; v += 0.02) Add(at, v, r);
    }
  }
};

// A car's rear face 40 m ahead, 1.8 m wide (bearings +-1.29 deg), on rings 30-35.
Cloud RearFace() {
  Cloud c;
  c.Face(40.0, -0.9, 0.9, 30, 35);
  return c;
}

const Eigen::Vector2d kSensor(0.0, 0.0);
const Eigen::Vector2d kLeft(40.0, 0.9), kRight(40.0, -0.9);

// The profile of c, per ring.
RangeProfile PerRing(const Cloud& c) {
  RangeProfile p;
  p.Build(kSensor, c.x, c.y, c.ring, kBinDeg);
  return p;
}

// Whether the rear face's left (right) end is seen free beyond it in p.
bool LeftEndFree(const RangeProfile& p) { return p.FreeBeyond(kLeft, kRight, kMargin, kBins); }
bool RightEndFree(const RangeProfile& p) { return p.FreeBeyond(kRight, kLeft, kMargin, kBins); }

TEST(RangeProfileTest, FaceEndingInFreeSpaceIsSeenWhole) {
  const RangeProfile p = PerRing(RearFace());
  EXPECT_TRUE(LeftEndFree(p));
  EXPECT_TRUE(RightEndFree(p));
}

TEST(RangeProfileTest, LowObjectNearTheSensorOnOtherRingsDoesNotHideTheFace) {
  // A bonnet 4 m ahead, 1.6 m wide (bearings +-11 deg, over both ends of the face), hit only by
  // the downward rings 0-5: the rings that see the face pass over it.
  Cloud c = RearFace();
  c.Face(4.0, -0.8, 0.8, 0, 5);
  const RangeProfile per_ring = PerRing(c);
  EXPECT_TRUE(LeftEndFree(per_ring));
  EXPECT_TRUE(RightEndFree(per_ring));
  // One profile over all rings (as before) reads the bonnet as an occluder beyond both ends.
  RangeProfile flat;
  flat.Build(kSensor, c.x, c.y, kBinDeg);
  EXPECT_FALSE(LeftEndFree(flat));
  EXPECT_FALSE(RightEndFree(flat));
}

TEST(RangeProfileTest, OccluderOnTheFaceRingsJustBeyondAnEndHidesIt) {
  // A pole 20 m ahead, 0.3 deg beyond the left end's bearing, on ring 32 (one of the face's).
  Cloud c = RearFace();
  const double bearing = std::atan2(0.9, 40.0) + DegToRad(0.3);
  for (double d = -0.05; d <= 0.05; d += 0.01) {
    c.Add(20.0 * std::cos(bearing + d / 20.0), 20.0 * std::sin(bearing + d / 20.0), 32);
  }
  const RangeProfile p = PerRing(c);
  EXPECT_FALSE(LeftEndFree(p));
  EXPECT_TRUE(RightEndFree(p));  // the other end is still free
}

TEST(RangeProfileTest, FaceContinuingAtTheSameRangeIsNotSeenWhole) {
  // The face goes on beyond the right end (y -0.9 .. -1.5) on ring 31: the fitted edge is only
  // part of it.
  Cloud c = RearFace();
  c.Face(40.0, -1.5, -0.95, 31, 31);
  const RangeProfile p = PerRing(c);
  EXPECT_FALSE(RightEndFree(p));
  EXPECT_TRUE(LeftEndFree(p));
}

TEST(RangeProfileTest, RingsOutsideTheTableShareTheLastAndNegativeOnesTheFirst) {
  // Out-of-range ring numbers must not index outside the table (clamped, not dropped).
  Cloud c = RearFace();
  c.Add(4.0, 0.0, -3);
  c.Add(4.0, 0.1, 30000);
  EXPECT_TRUE(LeftEndFree(PerRing(c)));
}

// Build() finds bins with a fast bearing and falls back to std::atan2 near bin edges: every
// return must land in the bin std::atan2 gives, also returns exactly on bin edges and at
// +-180 deg. Reference: per (ring, bin) the nearest range, binned with std::atan2 here.
TEST(RangeProfileTest, BinsAreThoseOfStdAtan2AlsoOnBinEdges) {
  const Eigen::Vector2d sensor(3.25, -7.5);
  constexpr int kRings = 4;
  for (const double bin_deg : {0.05, 0.2, 1.0}) {
    SCOPED_TRACE(bin_deg);
    const int n = static_cast<int>(std::ceil(360.0 / bin_deg));
    const double w = 2.0 * kPi / n;  // [rad]
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> bearing(-kPi, kPi), range(1.0, 80.0);
    std::vector<double> x, y, bearings;
    std::vector<std::int16_t> ring;
    for (int i = 0; i < 20000; ++i) bearings.push_back(bearing(rng));
    for (int b = 0; b <= n; b += 7) bearings.push_back(-kPi + b * w);  // on the edges
    bearings.push_back(kPi);
    for (std::size_t i = 0; i < bearings.size(); ++i) {
      const double r = range(rng);
      x.push_back(sensor.x() + r * std::cos(bearings[i]));
      y.push_back(sensor.y() + r * std::sin(bearings[i]));
      ring.push_back(static_cast<std::int16_t>(i % kRings));
    }
    std::vector<float> want(static_cast<std::size_t>(kRings * n), std::numeric_limits<float>::infinity());
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double dx = x[i] - sensor.x(), dy = y[i] - sensor.y();
      int b = static_cast<int>(std::floor((std::atan2(dy, dx) + kPi) * (n / (2.0 * kPi))));
      b = ((b % n) + n) % n;
      float& f = want[static_cast<std::size_t>(ring[i] * n + b)];
      f = std::min(f, static_cast<float>(std::hypot(dx, dy)));
    }
    RangeProfile p;
    p.Build(sensor, x, y, ring, bin_deg);
    ASSERT_EQ(p.num_bins(), n);
    ASSERT_EQ(p.num_rings(), kRings);
    int differ = 0;
    for (int r = 0; r < kRings; ++r) {
      for (int b = 0; b < n; ++b) differ += p.Nearest(r, b) != want[static_cast<std::size_t>(r * n + b)];
    }
    EXPECT_EQ(differ, 0);
  }
}

// SeenThrough: two parked cars' faces 40 m ahead with a 1 m gap between them (y -0.5 .. 0.5, 1.4
// deg, 7 bins), hit by rings 30-35; the rings above them (36-40) see a wall 5 m behind.
Cloud TwoCarsInARow(bool wall_behind) {
  Cloud c;
  c.Face(40.0, 0.5, 5.0, 30, 35);
  c.Face(40.0, -4.0, -0.5, 30, 35);
  if (wall_behind) c.Face(45.0, -6.0, 6.0, 36, 40);
  return c;
}
const Eigen::Vector2d kGapLeft(40.0, 0.5), kGapRight(40.0, -0.5);

TEST(RangeProfileTest, GapWithSomethingBehindItIsSeenThrough) {
  const RangeProfile p = PerRing(TwoCarsInARow(true));
  EXPECT_TRUE(p.SeenThrough(kGapLeft, kGapRight, kMargin));
  EXPECT_TRUE(p.SeenThrough(kGapRight, kGapLeft, kMargin));
  // Along one car's face there is no gap: its own returns fill the bins between.
  EXPECT_FALSE(p.SeenThrough({40.0, 1.0}, {40.0, 4.0}, kMargin));
}

TEST(RangeProfileTest, GapShowingNothingBehindItIsNotSeenThrough) {
  // No return at all in the gap: returns lost (dark paint, glass) look the same.
  EXPECT_FALSE(PerRing(TwoCarsInARow(false)).SeenThrough(kGapLeft, kGapRight, kMargin));
}

TEST(RangeProfileTest, GapWithAReturnNearTheFaceOrNearerIsNotSeenThrough) {
  for (const double at : {40.3, 20.0}) {  // within the margin behind the face; a pole in front
    SCOPED_TRACE(at);
    Cloud c = TwoCarsInARow(true);
    c.Add(at, 0.0, 33);
    EXPECT_FALSE(PerRing(c).SeenThrough(kGapLeft, kGapRight, kMargin));
  }
}

TEST(RangeProfileTest, AtLeastHalfTheGapMustShowSomethingBehind) {
  // The gap's ends lie in bins 896 and 903 (bearings -0.72 and +0.72 deg): six bins between,
  // three of them (900-902) at bearings 0-0.6 deg. A wall behind the gap from bearing `from` on.
  for (const auto& [from_deg, seen] :
       {std::pair{0.0015, true}, std::pair{0.21, false}, std::pair{-0.5, true}}) {
    SCOPED_TRACE(from_deg);
    Cloud c = TwoCarsInARow(false);
    c.Face(45.0, 45.0 * std::tan(DegToRad(from_deg)), 45.0 * std::tan(DegToRad(1.0)), 36, 40);
    EXPECT_EQ(PerRing(c).SeenThrough(kGapLeft, kGapRight, kMargin), seen);
  }
}

TEST(RangeProfileTest, GapMustHoldAWholeBin) {
  // Ends in neighbouring bins (899, 900): nothing between. Ends two bins apart (898, 900): bin
  // 899 between, and the wall seen in it.
  const RangeProfile p = PerRing(TwoCarsInARow(true));
  auto at_deg = [](double deg) { return Eigen::Vector2d(40.0, 40.0 * std::tan(DegToRad(deg))); };
  EXPECT_FALSE(p.SeenThrough(at_deg(0.03), at_deg(-0.03), kMargin));
  EXPECT_TRUE(p.SeenThrough(at_deg(0.1), at_deg(-0.3), kMargin));
}

TEST(RangeProfileTest, GapWhereTheSweepLostItsReturnsIsNotSeenThrough) {
  RangeProfile p = PerRing(TwoCarsInARow(true));
  p.MarkUnseen(DegToRad(-0.1), DegToRad(0.1));
  EXPECT_FALSE(p.SeenThrough(kGapLeft, kGapRight, kMargin));
}

TEST(RangeProfileTest, GapAcrossTheBearingOfMinus180DegIsSeenThrough) {
  // The scene turned by 180 deg: the gap straddles the first and last bins.
  Cloud c = TwoCarsInARow(true);
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    c.x[i] = -c.x[i];
    c.y[i] = -c.y[i];
  }
  EXPECT_TRUE(PerRing(c).SeenThrough(-kGapLeft, -kGapRight, kMargin));
  EXPECT_FALSE(PerRing(c).SeenThrough({-40.0, -1.0}, {-40.0, -4.0}, kMargin));
}

}  // namespace
}  // namespace vtrack
