// A detector's boxes as measurements (tracker/core/detections.h), on seeded boxes with known
// truth: the heading taken modulo 180 deg, one-to-one association by centre distance, and the
// whole tracker in the boxes input mode following a car whose boxes are noisy and half of the
// time turned by 180 deg, while weak false boxes start no track.
#include "tracker/core/detections.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include "base/angle.h"
#include "tests/tracker/core/synthetic_scene.h"
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

// One box between a well-known track 0.7 m away (gate 2 + 3 * 0.1 = 2.3 m) and an uncertain
// one 1.6 m away (gate 2 + 3 * 1.0 = 5 m): the nearer, well-known track takes it. (With a
// track's own gate as its cost of going without a box, the uncertain one would: 0.7 + 5 > 1.6
// + 2.3.)
TEST(AssociateBoxes, AnUncertainTrackDoesNotOutbidANearerOne) {
  std::vector<PredictedObject> tracks(2);
  tracks[0].box.center = {0.0, 0.0};
  tracks[0].position_std = 0.1;
  tracks[1].box.center = {2.3, 0.0};
  tracks[1].position_std = 1.0;
  std::vector<BoxMeasurement> boxes(1);
  boxes[0].box.center = {0.7, 0.0};
  DetectionParams p;
  p.gate_m = 2.0;
  p.gate_sigma = 3.0;
  p.max_gate_m = 5.0;
  const BoxAssociation a = AssociateBoxes(tracks, boxes, p);
  ASSERT_EQ(a.track_box.size(), 2u);
  EXPECT_EQ(a.track_box[0], 0);
  EXPECT_EQ(a.track_box[1], -1);
  EXPECT_TRUE(a.new_boxes.empty());
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

// A car shorter and narrower than the default rectangle (4.5 x 1.8 m): its boxes, each a full
// view, give its size; it is not lengthened to the default.
TEST(TrackerBoxes, ReportsTheSizeOfTheBoxesNotTheDefaultRectangle) {
  TrackerParams params;
  params.detections.mode = InputMode::kBoxes;
  ASSERT_GT(params.manager.default_length, 4.0);
  ASSERT_GT(params.manager.default_width, 1.7);
  Tracker tracker(params);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1);
  constexpr double kLength = 3.6, kWidth = 1.55;  // [m]
  std::vector<ScanOutput> out;
  int checked = 0;
  for (int k = 0; k <= 30; ++k) {
    const std::int64_t t = kT0 + k * 100'000;
    tracker.AddPose({t, Eigen::Isometry3d::Identity()}, &out);
    DetectionList list;
    list.utime = t;
    list.seq = k;
    Detection d;
    d.x = 12.0 + noise(rng);
    d.y = 4.0 + noise(rng);
    d.yaw = 0.4;
    d.length = kLength + noise(rng);
    d.width = kWidth + noise(rng);
    d.height = 1.5;
    d.score = 6.0;
    list.boxes.push_back(d);
    out.clear();
    tracker.AddDetections(std::move(list), &out);
    tracker.AddPose({t + 50'000, Eigen::Isometry3d::Identity()}, &out);
    for (const ScanOutput& o : out) {
      for (const TrackReport& r : o.tracks) {
        if (k < 10 || r.status != TrackStatus::kConfirmed) continue;
        ++checked;
        EXPECT_NEAR(r.length, kLength, 0.25) << "frame " << k;
        EXPECT_NEAR(r.width, kWidth, 0.25) << "frame " << k;
        EXPECT_EQ(r.object_class, ObjectClass::kVehicle);
      }
    }
  }
  EXPECT_EQ(checked, 21);
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
    if (k >= 5) {
      EXPECT_EQ(tr[0].y > 0.0, tr[0].score > tr[1].score) << "frame " << k;
    }
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


// Fused input on the seeded single-plane scene: a parked car seen by the LADAR only and a
// turning car that the detector also boxes (0.1 m noise, at the middle of each sweep), with the
// detector silent for 0.5 s (frames 20-24) and for good from frame 40 on.
struct FusedRun {
  std::map<int, std::set<std::int64_t>> ids;             // object -> ids of tracks within 1.5 m
  std::map<int, std::map<int, ObjectClass>> class_at;   // object -> frame -> class of that track
  std::map<int, double> max_error;                       // object -> worst centre error [m]
};

FusedRun RunFused(bool vehicle_needs_box) {
  using testing::AckermannPath;
  const std::vector<testing::SceneObject> objects = {
      {1, AckermannPath({16.0, 7.0}, 0.3, 0.0, 0.0, -1.4)},  // parked: scans only
      {2, AckermannPath({4.0, -8.0}, 0.0, 7.0, 0.2, -1.4)},  // turning: scans and boxes
  };
  testing::SyntheticScene scene(testing::SceneConfig{}, objects, 11);
  TrackerParams params;
  params.detections.mode = InputMode::kFused;
  params.detections.fused_vehicle_needs_box = vehicle_needs_box;
  Tracker tracker(params);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.1);
  FusedRun run;
  std::vector<ScanOutput> out;
  for (int tick = 0; tick <= 600; ++tick) {
    const double t = tick * 0.01;
    tracker.AddPose(scene.PoseAt(t), &out);
    if (tick < 10 || tick % 10 != 0) continue;
    const int frame = tick / 10 - 1;
    const double t_scan = t - 0.1;
    if (frame < 20 || (frame >= 25 && frame < 40)) {
      const double t_box = t_scan + 0.05;  // the middle of the sweep, as KITTI's labels
      const OrientedBox b = objects[1].box_at(t_box);
      const Eigen::Isometry3d ego = scene.EgoAt(t_box);
      const Eigen::Vector3d c = ego.inverse() * Eigen::Vector3d(b.center.x(), b.center.y(), 0.0);
      DetectionList list;
      list.utime = scene.Utime(t_box);
      list.seq = frame;
      Detection d;
      d.x = c.x() + noise(rng);
      d.y = c.y() + noise(rng);
      d.yaw = b.theta;  // the ego does not turn
      d.length = b.length;
      d.width = b.width;
      d.height = 1.5;
      d.score = 8.0;
      list.boxes.push_back(d);
      tracker.AddDetections(std::move(list), &out);
    }
    out.clear();
    tracker.AddScan(scene.ScanAt(t_scan, frame), &out);
    for (const ScanOutput& o : out) {
      const double to = (o.utime - scene.Utime(0.0)) * 1e-6;
      for (const auto& obj : objects) {
        const OrientedBox truth = obj.box_at(to + 0.05);
        for (const TrackReport& r : o.tracks) {
          if (r.status != TrackStatus::kConfirmed) continue;
          const double e = std::hypot(r.x - truth.center.x(), r.y - truth.center.y());
          if (e > 1.5) continue;
          run.ids[obj.id].insert(r.id);
          run.class_at[obj.id][frame] = r.object_class;
          if (frame >= 10) run.max_error[obj.id] = std::max(run.max_error[obj.id], e);
        }
      }
    }
  }
  return run;
}

TEST(TrackerFused, TheDetectorDecidesTheVehicleClassAndScansCarryTheTrackThroughItsGaps) {
  const FusedRun run = RunFused(true);
  // Both cars tracked, each by one track all along.
  ASSERT_EQ(run.ids.count(1), 1u);
  ASSERT_EQ(run.ids.count(2), 1u);
  EXPECT_EQ(run.ids.at(1).size(), 1u);
  EXPECT_EQ(run.ids.at(2).size(), 1u);
  // The parked car has no box: a track, but not a vehicle, whatever its size.
  for (const auto& [frame, c] : run.class_at.at(1)) EXPECT_EQ(c, ObjectClass::kOther) << frame;
  // The boxed car: a vehicle from its third box on, through the detector's 0.5 s gap (scans
  // update it), and no longer 1.5 s (manager.coast_max_s) after the detector's last box.
  const auto& car = run.class_at.at(2);
  for (int frame : {5, 15, 21, 24, 30, 39, 40, 53}) {
    ASSERT_TRUE(car.count(frame)) << "frame " << frame;
    EXPECT_EQ(car.at(frame), ObjectClass::kVehicle) << "frame " << frame;
  }
  for (int frame : {55, 57}) {
    ASSERT_TRUE(car.count(frame)) << "frame " << frame;
    EXPECT_EQ(car.at(frame), ObjectClass::kOther) << "frame " << frame;
  }
  EXPECT_LT(run.max_error.at(2), 0.6);
}

TEST(TrackerFused, WithoutTheSwitchTheSizeRulesClassTheParkedCarAVehicle) {
  const FusedRun run = RunFused(false);
  ASSERT_EQ(run.class_at.count(1), 1u);
  int vehicle = 0;
  for (const auto& [frame, c] : run.class_at.at(1)) vehicle += c == ObjectClass::kVehicle;
  EXPECT_GT(vehicle, 20);
}

}  // namespace
}  // namespace vtrack

namespace vtrack {
namespace {

// Detection lists lost on the way show as gaps in their seq: one count per missing list, as for
// scans; lists whose pose cannot be found have reasons of their own (not the scans' reasons).
TEST(TrackerBoxes, LostListsAreCountedFromSeqGaps) {
  TrackerParams params;
  params.detections.mode = InputMode::kBoxes;
  Tracker tracker(params);
  std::vector<ScanOutput> out;
  int lost = 0;
  for (int k = 0; k < 40; ++k) {
    const std::int64_t t = kT0 + k * 100'000;
    tracker.AddPose({t, Eigen::Isometry3d::Identity()}, &out);
    if (k % 7 == 3 || (k >= 20 && k < 25)) {
      ++lost;
      continue;
    }
    DetectionList list;
    list.utime = t;
    list.seq = 1000 + k;
    tracker.AddDetections(std::move(list), &out);
  }
  ASSERT_GT(lost, 5);
  EXPECT_EQ(tracker.rejects().at("detections_seq_gap"), lost);
  EXPECT_EQ(tracker.rejects().count("scan_seq_gap"), 0u);
}

// Lists waiting for poses when the input resets (a jump in time confirmed by the next message)
// are dropped and counted.
TEST(TrackerBoxes, ListsQueuedAtAResetAreCounted) {
  TrackerParams params;
  params.detections.mode = InputMode::kBoxes;
  Tracker tracker(params);
  std::vector<ScanOutput> out;
  for (int k = 0; k < 3; ++k) {  // no pose yet: they wait
    DetectionList list;
    list.utime = kT0 + k * 10'000;
    list.seq = k;
    tracker.AddDetections(std::move(list), &out);
  }
  const std::int64_t hour = 3'600'000'000;
  tracker.AddPose({kT0 + hour, Eigen::Isometry3d::Identity()}, &out);           // refused
  tracker.AddPose({kT0 + hour + 10'000, Eigen::Isometry3d::Identity()}, &out);  // confirms: reset
  EXPECT_EQ(tracker.resets(), 1);
  EXPECT_EQ(tracker.rejects().at("detections_reset"), 3);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace vtrack
