#include "base/pose.h"

#include <gtest/gtest.h>

#include "base/angle.h"

namespace vtrack {
namespace {

Eigen::Isometry3d Pose(double x, double y, double yaw) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = QuaternionFromRpy(0, 0, yaw).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, y, 0);
  return p;
}

TEST(Pose, InterpolateYawAndTranslation) {
  const auto a = Pose(0, 0, 0.0), b = Pose(10, 4, kPi / 2);
  const auto m = InterpolatePose(a, b, 0.25);
  EXPECT_NEAR(m.translation().x(), 2.5, 1e-12);
  EXPECT_NEAR(m.translation().y(), 1.0, 1e-12);
  EXPECT_NEAR(YawOf(m), kPi / 8, 1e-12);
}

TEST(Pose, InterpolateAcrossPi) {
  const auto m = InterpolatePose(Pose(0, 0, kPi - 0.1), Pose(0, 0, -kPi + 0.1), 0.5);
  EXPECT_NEAR(std::abs(YawOf(m)), kPi, 1e-9);
}

TEST(Pose, ExtrapolateAtConstantRates) {
  const auto m = InterpolatePose(Pose(0, 0, 0.0), Pose(1, 0, 0.1), 3.0);
  EXPECT_NEAR(m.translation().x(), 3.0, 1e-12);
  EXPECT_NEAR(YawOf(m), 0.3, 1e-9);
}

TEST(PoseHistory, LookupStatuses) {
  PoseHistory h(1'000'000);
  PoseHistory::LookupStatus s;
  EXPECT_FALSE(h.At(0, 0, &s));
  EXPECT_EQ(s, PoseHistory::LookupStatus::kEmpty);
  ASSERT_EQ(h.Add(1000, Pose(0, 0, 0)), PoseHistory::AddResult::kOk);
  ASSERT_EQ(h.Add(11000, Pose(1, 0, 0)), PoseHistory::AddResult::kOk);
  EXPECT_EQ(h.Add(11000, Pose(9, 9, 0)), PoseHistory::AddResult::kDuplicate);
  EXPECT_EQ(h.Add(5000, Pose(9, 9, 0)), PoseHistory::AddResult::kOutOfOrder);
  auto p = h.At(6000, 0, &s);
  ASSERT_TRUE(p);
  EXPECT_EQ(s, PoseHistory::LookupStatus::kOk);
  EXPECT_NEAR(p->translation().x(), 0.5, 1e-12);
  EXPECT_FALSE(h.At(500, 0, &s));
  EXPECT_EQ(s, PoseHistory::LookupStatus::kBeforeHistory);
  p = h.At(16000, 10000, &s);
  ASSERT_TRUE(p);
  EXPECT_EQ(s, PoseHistory::LookupStatus::kExtrapolated);
  EXPECT_NEAR(p->translation().x(), 1.5, 1e-12);
  EXPECT_FALSE(h.At(30000, 10000, &s));
  EXPECT_EQ(s, PoseHistory::LookupStatus::kTooFarAhead);
}

TEST(PoseHistory, DropsPosesOlderThanSpan) {
  PoseHistory h(100);
  for (int t = 0; t <= 1000; t += 10) h.Add(t, Pose(t, 0, 0));
  EXPECT_GE(h.oldest_utime(), 900);
  EXPECT_EQ(h.newest_utime(), 1000);
}

}  // namespace
}  // namespace vtrack
