#include "base/box.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "base/angle.h"

namespace vtrack {
namespace {

constexpr double kSlant = 10.0 * kPi / 180.0;

TEST(Box, CornersAreRotatedHalfExtents) {
  OrientedBox b{{3.0, -2.0}, kPi / 2, 4.0, 2.0};  // pointing +y
  const auto c = b.Corners();
  // Front-left of a box pointing +y is at (+y front, -x left): (3 - 1, -2 + 2).
  EXPECT_NEAR(c[0].x(), 2.0, 1e-12); EXPECT_NEAR(c[0].y(), 0.0, 1e-12);
  EXPECT_NEAR(c[1].x(), 2.0, 1e-12); EXPECT_NEAR(c[1].y(), -4.0, 1e-12);
  EXPECT_NEAR(c[2].x(), 4.0, 1e-12); EXPECT_NEAR(c[2].y(), -4.0, 1e-12);
  EXPECT_NEAR(c[3].x(), 4.0, 1e-12); EXPECT_NEAR(c[3].y(), 0.0, 1e-12);
}

TEST(Box, ContainsAgreesWithHalfPlaneTest) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-5, 5);
  OrientedBox b{{0.5, 0.3}, 0.7, 4.5, 1.8};
  const auto c = b.Corners();
  for (int i = 0; i < 5000; ++i) {
    const Eigen::Vector2d p(u(rng), u(rng));
    // Independent reference: inside a convex CCW polygon iff left of every edge.
    bool inside = true;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d e = c[(k + 1) % 4] - c[k], d = p - c[k];
      if (e.x() * d.y() - e.y() * d.x() < 0) inside = false;
    }
    EXPECT_EQ(b.Contains(p), inside) << p.transpose();
  }
}

TEST(Box, FrameRoundTrip) {
  OrientedBox b{{10, 20}, -2.5, 5, 2};
  const Eigen::Vector2d p(7.5, 18.25);
  EXPECT_LT((b.ToWorld(b.ToBoxFrame(p)) - p).norm(), 1e-12);
}

TEST(Box, FaceNormalsPointOutward) {
  OrientedBox b{{1, 1}, 0.3, 4, 2};
  for (int i = 0; i < 4; ++i) {
    const Face f = static_cast<Face>(i);
    const double a = b.OutwardNormalAngle(f);
    const Eigen::Vector2d outside = b.FaceMidpoint(f) + 0.01 * Eigen::Vector2d(std::cos(a), std::sin(a));
    EXPECT_FALSE(b.Contains(outside));
    const Eigen::Vector2d inside = b.FaceMidpoint(f) - 0.01 * Eigen::Vector2d(std::cos(a), std::sin(a));
    EXPECT_TRUE(b.Contains(inside));
  }
}

TEST(Box, VisibleFacesFromAhead) {
  OrientedBox b{{0, 0}, 0.0, 4, 2};
  EXPECT_EQ(VisibleFaces(b, {20, 0}, kSlant), 1u << 0);        // front only
  EXPECT_EQ(VisibleFaces(b, {-20, 0}, kSlant), 1u << 2);       // rear only
  EXPECT_EQ(VisibleFaces(b, {0, 20}, kSlant), 1u << 1);        // left only
  EXPECT_EQ(VisibleFaces(b, {20, 20}, kSlant), (1u << 0) | (1u << 1));
  EXPECT_EQ(VisibleFaces(b, {-20, -20}, kSlant), (1u << 2) | (1u << 3));
}

TEST(Box, GrazingFaceIsNotVisible) {
  // Sensor far ahead and slightly to the left: the left face is seen at a slant of about
  // atan(lateral / distance) < 10 deg, so only the front counts (Eq. 15, s = 10 deg).
  OrientedBox b{{0, 0}, 0.0, 4, 2};
  EXPECT_EQ(VisibleFaces(b, {50, 5}, kSlant), 1u << 0);
  // At 15 deg of slant the left face is visible.
  const double d = 50.0;
  EXPECT_EQ(VisibleFaces(b, {d, 1.0 + d * std::tan(15.0 * kPi / 180.0)}, kSlant),
            (1u << 0) | (1u << 1));
}

}  // namespace
}  // namespace vtrack
