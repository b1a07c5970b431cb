// Sweeps with lost wedges (LadarScan::lost_wedges: slices that did not arrive): a track whose
// predicted centre lies in a lost wedge is not observed by that sweep and keeps its miss count;
// a track outside every lost wedge that gets no returns is missed as usual. Two parked cars on a
// seeded synthetic scene; after they are tracked, their returns vanish for three sweeps, with the
// bearing of one car (computed here from the truth and the ego pose) declared lost.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/tracker/core/synthetic_scene.h"
#include "tracker/core/tracker.h"

namespace vtrack {
namespace {

using testing::AckermannPath;
using testing::SceneConfig;
using testing::SceneObject;
using testing::SyntheticScene;

const Eigen::Vector2d kCarA(14.0, 8.0), kCarB(14.0, -8.0);

std::vector<SceneObject> Wall() {
  // A long box behind the ego vehicle, so that a sweep without the cars still has returns.
  return {{3, AckermannPath({-15.0, 0.0}, 1.5708, 0.0, 0.0, -1.4, 12.0, 1.0)}};
}

std::vector<SceneObject> CarsAndWall() {
  std::vector<SceneObject> objs = {{1, AckermannPath(kCarA, 0.0, 0.0, 0.0, -1.4)},
                                   {2, AckermannPath(kCarB, 0.0, 0.0, 0.0, -1.4)}};
  objs.push_back(Wall()[0]);
  return objs;
}

const Track* TrackNear(const Tracker& tracker, const Eigen::Vector2d& p) {
  for (std::size_t j = 0; j < tracker.manager().tracks().size(); ++j) {
    if ((tracker.manager().Box(j).center - p).norm() < 2.0) return &tracker.manager().tracks()[j];
  }
  return nullptr;
}

// 2 s with both cars (tracks confirmed), then three sweeps without them; with_wedge: those
// sweeps declare car A's bearing (+-10 deg) lost.
void RunWithVanishingCars(bool with_wedge, Tracker* tracker) {
  SceneConfig cfg;
  cfg.ego_speed = 0.0;  // the bearing of car A from the sensor stays put
  SyntheticScene full(cfg, CarsAndWall(), 21), empty(cfg, Wall(), 22);
  std::vector<ScanOutput> out;
  std::int64_t seq = 0;
  for (int tick = 0; tick <= 230; ++tick) {
    const double t = tick * 0.01;
    tracker->AddPose(full.PoseAt(t), &out);
    if (tick < 10 || tick % 10 != 0) continue;
    const double t0 = t - 0.1;
    if (tick <= 200) {
      tracker->AddScan(full.ScanAt(t0, seq++), &out);
      continue;
    }
    LadarScan scan = empty.ScanAt(t0, seq++);
    if (with_wedge) {
      // Bearing of car A in the sensor frame (= body frame here) at mid-sweep.
      const Eigen::Isometry3d ego = full.EgoAt(t0 + 0.05);
      const Eigen::Vector3d a = ego.inverse() * Eigen::Vector3d(kCarA.x(), kCarA.y(), 0.0);
      const double bearing = std::atan2(a.y(), a.x());
      scan.lost_wedges.push_back({bearing - DegToRad(10.0), bearing + DegToRad(10.0)});
    }
    tracker->AddScan(std::move(scan), &out);
  }
  tracker->Flush(&out);
}

TEST(LostWedgeTest, TrackInALostWedgeIsNotMissedOneOutsideIs) {
  Tracker tracker(TrackerParams{});
  RunWithVanishingCars(/*with_wedge=*/true, &tracker);
  const Track* a = TrackNear(tracker, kCarA);
  const Track* b = TrackNear(tracker, kCarB);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(a->consecutive_misses, 0);
  EXPECT_EQ(a->status, TrackStatus::kConfirmed);
  EXPECT_EQ(b->consecutive_misses, 3);
  EXPECT_EQ(b->status, TrackStatus::kCoasting);
  EXPECT_EQ(tracker.rejects().at("sweep_partial"), 3);
  EXPECT_EQ(tracker.rejects().at("track_in_lost_wedge"), 3);
}

TEST(LostWedgeTest, WithoutTheWedgeBothAreMissed) {
  Tracker tracker(TrackerParams{});
  RunWithVanishingCars(/*with_wedge=*/false, &tracker);
  const Track* a = TrackNear(tracker, kCarA);
  const Track* b = TrackNear(tracker, kCarB);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(a->consecutive_misses, 3);
  EXPECT_EQ(b->consecutive_misses, 3);
  EXPECT_EQ(tracker.rejects().count("sweep_partial"), 0u);
}

TEST(LostWedgeTest, WedgeContainsAcrossTheSeam) {
  const AzimuthWedge w{DegToRad(170.0), DegToRad(190.0)};  // across +-180 deg
  EXPECT_TRUE(w.Contains(DegToRad(175.0)));
  EXPECT_TRUE(w.Contains(DegToRad(-175.0)));  // 185 deg
  EXPECT_FALSE(w.Contains(DegToRad(-165.0)));  // 195 deg
  EXPECT_FALSE(w.Contains(DegToRad(160.0)));
}

}  // namespace
}  // namespace vtrack
