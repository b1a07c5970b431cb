// RangeProfile (track_manager.h): whether a fitted face is seen whole, checked against scenes
// built by hand whose answer follows from the geometry: a face ends in free space, behind a low
// object near the sensor that only the downward rings hit, behind a real occluder on the face's
// rings, or continues at the same range.
#include "tracker/core/range_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
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

}  // namespace
}  // namespace vtrack
