// A detector's boxes as measurements (tracker/core/detections.h), on seeded boxes with known
// truth: the heading taken modulo 180 deg, one-to-one association by centre distance, and the
// whole tracker in the boxes input mode following a car whose boxes are noisy and half of the
// time turned by 180 deg, while weak false boxes start no track.
#include "tracker/core/detections.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "base/angle.h"
#include "tracker/core/tracker.h"

namespace vtrack {
namespace {

constexpr std::int64_t kT0 = 1'600'000'000'000'000;

TEST(BoxToMeasurement, TakesTheBoxHeadingOrItsOppositeWhicheverIsNearer) {
  BoxMeasurement b;
  b.box.center = {3.0, -2.0};
  b.box.theta = DegToRad(170.0);
  DetectionParams p;
  p.position_std = 0.2;
  p.heading_std_deg = 4.0;
  // A hypothesis heading -5 deg: the box's 170 deg is -10 deg seen from the other end.
  const CentreMeasurement m = BoxToMeasurement(b, DegToRad(-5.0), p);
  EXPECT_NEAR(m.z(0), 3.0, 1e-12);
  EXPECT_NEAR(m.z(1), -2.0, 1e-12);
  EXPECT_NEAR(RadToDeg(m.z(2)), -10.0, 1e-9);
  // Heading 150 deg: the box's own heading is nearer.
  EXPECT_NEAR(RadToDeg(BoxToMeasurement(b, DegToRad(150.0), p).z(2)), 170.0, 1e-9);
  // Near +-180 the measurement stays within 90 deg of the hypothesis (no wrap in the innovation).
  EXPECT_NEAR(RadToDeg(BoxToMeasurement(b, DegToRad(-175.0), p).z(2)), -190.0, 1e-9);
  EXPECT_NEAR(m.R(0, 0), 0.04, 1e-12);
  EXPECT_NEAR(m.R(1, 1), 0.04, 1e-12);
  EXPECT_NEAR(m.R(2, 2), std::pow(DegToRad(4.0), 2), 1e-15);
  EXPECT_EQ(m.R(0, 1), 0.0);
}

TEST(AssociateBoxes, PairsOneToOneByDistanceWithinTheGate) {
  std::vector<PredictedObject> tracks(3);
  tracks[0].box.center = {0.0, 0.0};
  tracks[1].box.center = {1.5, 0.0};
  tracks[2].box.center = {20.0, 0.0};
  std::vector<BoxMeasurement> boxes(3);
  boxes[0].box.center = {1.4, 0.0};   // nearest to track 1 (0.1 m), 1.4 m from track 0
  boxes[1].box.center = {-0.3, 0.0};  // 0.3 m from track 0
  boxes[2].box.center = {26.0, 0.0};  // 6 m from track 2: outside its gate
  DetectionParams p;
  p.gate_m = 2.0;
  p.gate_sigma = 0.0;
  const BoxAssociation a = AssociateBoxes(tracks, boxes, p);
  ASSERT_EQ(a.track_box.size(), 3u);
  EXPECT_EQ(a.track_box[0], 1);
  EXPECT_EQ(a.track_box[1], 0);
  EXPECT_EQ(a.track_box[2], -1);
  EXPECT_EQ(a.new_boxes, std::vector<int>{2});
}

TEST(BoxesInWorld, PlacesBoxesWithTheEgoPoseAndDropsWeakOnes) {
  DetectionList list;
  list.utime = kT0;
  Detection d;
  d.x = 10.0;
  d.y = 0.0;
  d.yaw = 0.0;
  d.length = 4.0;
  d.width = 1.8;
  d.height = 1.5;
  d.score = 5.0;
  list.boxes.push_back(d);
  d.score = -3.0;  // below min_score
  list.boxes.push_back(d);
  // Ego at (100, 50) heading 90 deg: the box 10 m ahead is at (100, 60), heading 90 deg.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.5 * kPi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(100.0, 50.0, 0.0);
  DetectionParams p;
  p.min_score = 0.0;
  const auto boxes = BoxesInWorld(list, pose, p);
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_NEAR(boxes[0].box.center.x(), 100.0, 1e-9);
  EXPECT_NEAR(boxes[0].box.center.y(), 60.0, 1e-9);
  EXPECT_NEAR(boxes[0].box.theta, 0.5 * kPi, 1e-9);
  EXPECT_EQ(boxes[0].utime, kT0);
}

TEST(TrackerBoxes, FollowsACarWhoseBoxesAreNoisyAndOftenTurnedAround) {
  TrackerParams params;
  params.detections.mode = InputMode::kBoxes;
  params.detections.min_score = 0.0;
  params.detections.birth_score = 1.0;
  Tracker tracker(params);
  std::mt19937 rng(7);
  std::normal_distribution<double> pos(0.0, 0.1), head(0.0, DegToRad(2.0));
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double heading = DegToRad(30.0), speed = 10.0;  // [rad], [m/s]
  const Eigen::Vector2d start(5.0, -3.0);
  std::vector<ScanOutput> out;
  std::set<std::int64_t> ids;
  int frames_checked = 0;
  for (int k = 0; k <= 40; ++k) {  // 4 s at 10 Hz
    const std::int64_t t = kT0 + k * 100'000;
    // The ego stands at the origin; poses bracket every frame.
    tracker.AddPose({t, Eigen::Isometry3d::Identity()}, &out);
    DetectionList list;
    list.utime = t;
    list.seq = k;
    const Eigen::Vector2d c = start + speed * (k * 0.1) * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    Detection d;
    d.x = c.x() + pos(rng);
    d.y = c.y() + pos(rng);
    d.yaw = WrapToPi(heading + head(rng) + (uni(rng) < 0.5 ? kPi : 0.0));
    d.length = 4.4;
    d.width = 1.8;
    d.height = 1.5;
    d.score = 6.0;
    list.boxes.push_back(d);
    Detection weak = d;  // a weak false box 15 m aside: never a track
    weak.x += 15.0;
    weak.score = 0.5;
    list.boxes.push_back(weak);
    out.clear();
    tracker.AddDetections(std::move(list), &out);
    tracker.AddPose({t + 50'000, Eigen::Isometry3d::Identity()}, &out);
    for (const ScanOutput& o : out) {
      EXPECT_LE(o.tracks.size(), 1u) << "frame " << k;
      for (const TrackReport& r : o.tracks) {
        ids.insert(r.id);
        if (k < 20 || r.status != TrackStatus::kConfirmed) continue;
        ++frames_checked;
        EXPECT_LT(std::hypot(r.x - c.x(), r.y - c.y()), 0.3) << "frame " << k;
        EXPECT_LT(std::abs(std::sin(AngleDiff(r.theta, heading))), std::sin(DegToRad(5.0))) << "frame " << k;
        EXPECT_NEAR(r.speed, speed, 1.0) << "frame " << k;
        EXPECT_EQ(r.object_class, ObjectClass::kVehicle);
      }
    }
  }
  EXPECT_EQ(ids.size(), 1u);
  EXPECT_EQ(frames_checked, 21);
  EXPECT_EQ(tracker.rejects().count("bad_detections"), 0u);
}

// Two cars side by side whose boxes come with seeded random scores, one car's higher on the
// whole: each track's score is the recency-weighted mean of its own boxes' scores (computed here
// with explicit weights: the plain mean of the first score_memory boxes, then each later box
// weighted 1 / score_memory), and ranks the cars.
TEST(TrackerBoxes, TrackScoreIsTheRecencyWeightedMeanOfItsBoxesScores) {
  TrackerParams params;
  params.detections.mode = InputMode::kBoxes;
  params.detections.min_score = -10.0;
  params.detections.birth_score = -10.0;
  params.detections.score_memory = 4.0;
  Tracker tracker(params);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> strong(4.0, 12.0), weak(-1.0, 5.0);
  std::vector<double> scores[2];
  std::vector<ScanOutput> out;
  int checked = 0;
  for (int k = 0; k < 15; ++k) {
    const std::int64_t t = kT0 + k * 100'000;
    tracker.AddPose({t, Eigen::Isometry3d::Identity()}, &out);
    DetectionList list;
    list.utime = t;
    list.seq = k;
    for (int car = 0; car < 2; ++car) {
      Detection d;
      d.x = 10.0 + 0.8 * k;
      d.y = car == 0 ? 4.0 : -4.0;
      d.z = car == 0 ? -1.6 : -1.9;  // bottom, body frame = world here
      d.length = 4.4;
      d.width = 1.8;
      d.height = car == 0 ? 1.5 : 2.4;
      d.score = car == 0 ? strong(rng) : weak(rng);
      scores[car].push_back(d.score);
      list.boxes.push_back(d);
    }
    out.clear();
    tracker.AddDetections(std::move(list), &out);
    ASSERT_EQ(out.size(), 1u);
    ASSERT_EQ(out[0].tracks.size(), 2u);
    for (const TrackReport& r : out[0].tracks) {
      const std::vector<double>& s = scores[r.y > 0.0 ? 0 : 1];
      const std::size_t n = s.size(), N = 4;
      double expected = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        // Box i's weight: 1/min(n, N) within the first N, scaled by (1 - 1/N) per later box;
        // a later box j > N: (1/N) (1 - 1/N)^(n - 1 - j).
        const double w = i < N ? std::pow(1.0 - 1.0 / N, static_cast<double>(n > N ? n - N : 0)) /
                                     static_cast<double>(std::min(n, N))
                               : std::pow(1.0 - 1.0 / N, static_cast<double>(n - 1 - i)) / N;
        expected += w * s[i];
      }
      EXPECT_NEAR(r.score, expected, 1e-9) << "frame " << k;
      // Bottom and height from the same boxes (constant per car here).
      EXPECT_NEAR(r.z, r.y > 0.0 ? -1.6 : -1.9, 1e-9) << "frame " << k;
      EXPECT_NEAR(r.height, r.y > 0.0 ? 1.5 : 2.4, 1e-9) << "frame " << k;
      ++checked;
    }
    const auto& tr = out[0].tracks;
    if (k >= 5) EXPECT_EQ(tr[0].y > 0.0, tr[0].score > tr[1].score) << "frame " << k;
  }
  EXPECT_EQ(checked, 30);
}

TEST(TrackerBoxes, RefusesAListWithANonFiniteBoxAndIgnoresBoxesWithScansOnly) {
  TrackerParams params;
  params.detections.mode = InputMode::kBoxes;
  Tracker tracker(params);
  std::vector<ScanOutput> out;
  DetectionList list;
  list.utime = kT0;
  Detection d;
  d.x = std::numeric_limits<double>::quiet_NaN();
  d.length = d.width = d.height = 1.0;
  list.boxes.push_back(d);
  tracker.AddDetections(std::move(list), &out);
  EXPECT_EQ(tracker.rejects().at("bad_detections"), 1);

  TrackerParams scans_only;  // the default: boxes are not used, nothing is counted
  Tracker t2(scans_only);
  DetectionList l2;
  l2.utime = kT0;
  l2.boxes.push_back(d);
  t2.AddDetections(std::move(l2), &out);
  EXPECT_TRUE(t2.rejects().empty());
}

}  // namespace
}  // namespace vtrack
