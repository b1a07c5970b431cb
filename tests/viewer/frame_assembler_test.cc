// Frame assembly and scene building from messages with known content: points back at their
// known world positions, one frame per TRACKS message (or per scan) whatever the arrival order,
// recent paths equal to the positions reported before, true paths around the frame time.
#include <gtest/gtest.h>

#include <memory>
#include <set>

#include "tests/viewer/test_messages.h"
#include "base/angle.h"
#include "base/pose.h"
#include "viewer/frame_assembler.h"
#include "viewer/msg_convert.h"
#include "viewer/scene_builder.h"

namespace vtrack::viewer {
namespace {

using testing::BodyFromSensor;
using testing::DebugFor;
using testing::EgoArc;
using testing::EmptyScan;
using testing::ScanOf;
using testing::TrackAt;
using testing::TrackList;
using testing::TruthAt;

constexpr std::int64_t kPeriod = 100'000;  // [us] 10 Hz scans

template <class T>
std::shared_ptr<const T> Share(T msg) {
  return std::make_shared<const T>(std::move(msg));
}

AssemblerParams Params(AssemblerParams::Trigger trigger) {
  AssemblerParams p;
  p.trigger = trigger;
  return p;
}

SceneParams TwoDimensional() {
  SceneParams p;
  p.preprocess.min_range = 0.5;
  return p;
}

void AddPoses(FrameAssembler* a, const EgoArc& ego, std::int64_t from, std::int64_t to) {
  for (std::int64_t t = from; t <= to; t += 10'000) a->AddPose(ego.Pose(t));
}

// Every return is placed in the world with the ego pose at its own time: with the ego turning at
// 0.3 rad/s and driving at 10 m/s, returns across a 100 ms sweep come back to the world points
// the scan was made from (within the pose interpolation error, v omega dt^2 / 8 ~ 4e-5 m).
TEST(SceneBuilderTest, PointsBackAtTheirWorldPositions) {
  const EgoArc ego;
  std::vector<Eigen::Vector3d> world;
  std::vector<std::int32_t> dt;
  for (int i = 0; i < 90; ++i) {
    const double a = -1.2 + 0.03 * i;
    const Eigen::Vector3d sensor = ego.WorldFromBody(ego.t0) * BodyFromSensor().translation();
    world.push_back(sensor + Eigen::Vector3d(12.0 * std::cos(a + ego.yaw0),
                                             12.0 * std::sin(a + ego.yaw0), -0.5 + 0.01 * i));
    dt.push_back(static_cast<std::int32_t>(i * 1100));
  }
  FrameAssembler a(Params(AssemblerParams::Trigger::kScans));
  AddPoses(&a, ego, ego.t0 - 200'000, ego.t0 + 600'000);
  a.AddScan(Share(ScanOf(ego, ego.t0, 1, world, dt)));
  const auto frames = a.Flush();
  ASSERT_EQ(frames.size(), 1u);
  SceneBuilder builder(TwoDimensional());
  const Scene s = builder.Build(frames[0]);
  ASSERT_EQ(s.points.size(), world.size());
  for (std::size_t i = 0; i < world.size(); ++i) {
    EXPECT_NEAR(s.points[i].x(), world[i].x(), 1e-3) << i;
    EXPECT_NEAR(s.points[i].y(), world[i].y(), 1e-3) << i;
  }
  // Without motion compensation the last returns would be ~1 m off: the test can tell.
  const Eigen::Vector3d uncompensated =
      ego.WorldFromBody(ego.t0) * BodyFromSensor() *
      (ego.WorldFromBody(ego.t0 + dt.back()) * BodyFromSensor()).inverse() * world.back();
  EXPECT_GT((uncompensated - world.back()).head<2>().norm(), 0.5);

  ASSERT_TRUE(s.ego.has_value());
  const Eigen::Isometry3d truth = ego.WorldFromBody(ego.t0);
  EXPECT_NEAR((s.ego->position - truth.translation().head<2>()).norm(), 0.0, 1e-6);
  EXPECT_NEAR(AngleDiff(s.ego->box.theta, ego.yaw0), 0.0, 1e-9);
  EXPECT_EQ(s.scan_seq, 1);
  EXPECT_TRUE(s.notes.empty()) << s.notes.front();
}

TEST(SceneBuilderTest, WithoutAnyPoseThePointsStayInTheVehicleFrame) {
  const EgoArc still{.t0 = 1'000'000, .x0 = 0.0, .y0 = 0.0, .yaw0 = 0.0, .v = 0.0, .omega = 1e-9};
  const std::vector<Eigen::Vector3d> body_points = {{10.0, 2.0, 0.0}, {5.0, -3.0, 0.5}};
  FrameAssembler a(Params(AssemblerParams::Trigger::kScans));
  a.AddScan(Share(ScanOf(still, still.t0, 4, body_points, {0, 50'000})));
  const auto frames = a.Flush();
  ASSERT_EQ(frames.size(), 1u);
  SceneBuilder builder(TwoDimensional());
  const Scene s = builder.Build(frames[0]);
  ASSERT_EQ(s.points.size(), 2u);
  EXPECT_NEAR(s.points[0].x(), 10.0, 1e-4);
  EXPECT_NEAR(s.points[1].y(), -3.0, 1e-4);
  EXPECT_FALSE(s.ego.has_value());
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("no ego pose"), std::string::npos);
}

// The tracker answers each scan after the next one has arrived, and its debug message comes
// after that: every frame still gets its own scan, tracks and debug.
TEST(FrameAssemblerTest, OneFramePerTracksMessageWhateverTheArrivalOrder) {
  const EgoArc ego;
  FrameAssembler a(Params(AssemblerParams::Trigger::kTracks));
  std::vector<FrameInputs> frames;
  constexpr int kScans = 20;
  for (int k = 0; k <= kScans; ++k) {
    const std::int64_t t = ego.t0 + k * kPeriod;
    AddPoses(&a, ego, t, t + kPeriod - 10'000);
    if (k < kScans) a.AddScan(Share(EmptyScan(t, k)));
    if (k > 0) {
      const auto list = TrackList(t - kPeriod, k - 1, {TrackAt(1, k, 0.0, 0.0)});
      a.AddTracks(Share(list));
      a.AddDebug(Share(DebugFor(list)));
    }
    for (auto& f : a.TakeReady()) frames.push_back(std::move(f));
  }
  for (auto& f : a.Flush()) frames.push_back(std::move(f));
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(kScans));
  for (int k = 0; k < kScans; ++k) {
    const auto& f = frames[static_cast<std::size_t>(k)];
    EXPECT_EQ(f.utime, ego.t0 + k * kPeriod);
    EXPECT_EQ(f.time_origin_utime, ego.t0);
    ASSERT_EQ(f.scans.size(), 1u);
    EXPECT_EQ(f.scans[0]->seq, k);
    ASSERT_TRUE(f.tracks);
    EXPECT_EQ(f.tracks->scan_seq, k);
    ASSERT_TRUE(f.debug) << k;
    EXPECT_EQ(f.debug->scan_seq, k);
  }
  EXPECT_EQ(a.stats().late_dropped, 0);
}

TEST(FrameAssemblerTest, ScansMakeFramesWhenThereAreNoTracks) {
  for (const auto trigger : {AssemblerParams::Trigger::kScans, AssemblerParams::Trigger::kAuto}) {
    FrameAssembler a(Params(trigger));
    int n = 0;
    for (int k = 0; k < 15; ++k) {
      a.AddScan(Share(EmptyScan(5'000'000 + k * kPeriod, k)));
      n += static_cast<int>(a.TakeReady().size());
    }
    n += static_cast<int>(a.Flush().size());
    EXPECT_EQ(n, 15);
  }
}

// Live, before the tracker starts, scans make frames; once TRACKS flow, TRACKS make them, and
// the scan and TRACKS of one moment are one frame.
TEST(FrameAssemblerTest, AutoTriggerSwitchesToTracksWithoutDuplicates) {
  FrameAssembler a(Params(AssemblerParams::Trigger::kAuto));
  std::vector<std::int64_t> utimes;
  for (int k = 0; k < 30; ++k) {
    const std::int64_t t = 9'000'000 + k * kPeriod;
    a.AddScan(Share(EmptyScan(t, k)));
    if (k >= 10) a.AddTracks(Share(TrackList(t, k, {TrackAt(1, 0, 0, 0)})));
    for (const auto& f : a.TakeReady()) utimes.push_back(f.utime);
  }
  for (const auto& f : a.Flush()) utimes.push_back(f.utime);
  ASSERT_EQ(utimes.size(), 30u);
  for (std::size_t i = 1; i < utimes.size(); ++i) EXPECT_EQ(utimes[i] - utimes[i - 1], kPeriod);
}

TEST(FrameAssemblerTest, TracksTooLateAreDroppedAndCountedNotReordered) {
  AssemblerParams p = Params(AssemblerParams::Trigger::kTracks);
  p.lag_us = 200'000;
  FrameAssembler a(p);
  std::vector<std::int64_t> utimes;
  for (int k = 0; k < 10; ++k) {
    const std::int64_t t = 1'000'000 + k * kPeriod;
    a.AddScan(Share(EmptyScan(t, k)));
    if (k != 3) a.AddTracks(Share(TrackList(t, k, {})));
    for (const auto& f : a.TakeReady()) utimes.push_back(f.utime);
  }
  // The answer to scan 3 comes 0.6 s late, after the frames up to scan 7 have been handed out.
  a.AddTracks(Share(TrackList(1'000'000 + 3 * kPeriod, 3, {})));
  for (const auto& f : a.TakeReady()) utimes.push_back(f.utime);
  for (const auto& f : a.Flush()) utimes.push_back(f.utime);
  EXPECT_EQ(a.stats().late_dropped, 1);
  EXPECT_EQ(a.stats().late_tracks, 1);
  EXPECT_EQ(utimes.size(), 9u);
  for (std::size_t i = 1; i < utimes.size(); ++i) EXPECT_GT(utimes[i], utimes[i - 1]);
}

// Live, a tracker started late (or restarted) answers scans that have already been drawn as scan
// frames (kAuto): the answer to the last drawn scan is never drawn either, and is counted.
TEST(FrameAssemblerTest, TracksForAScanFrameAlreadyHandedOutAreCountedLate) {
  AssemblerParams p = Params(AssemblerParams::Trigger::kAuto);
  p.lag_us = 200'000;
  FrameAssembler a(p);
  std::vector<FrameInputs> frames;
  const auto take = [&] {
    for (auto& f : a.TakeReady()) frames.push_back(std::move(f));
  };
  for (int k = 0; k < 15; ++k) {  // no tracker yet: a frame per scan
    a.AddScan(Share(EmptyScan(1'000'000 + k * kPeriod, k)));
    take();
  }
  // Handed out: the scans up to 12 (scan 14's time is 12's plus the lag).
  ASSERT_EQ(frames.size(), 13u);
  ASSERT_EQ(frames.back().utime, 1'000'000 + 12 * kPeriod);
  a.AddTracks(Share(TrackList(1'000'000 + 12 * kPeriod, 12, {})));  // after its frame
  a.AddTracks(Share(TrackList(1'000'000 + 13 * kPeriod, 13, {})));  // its frame still pending
  take();
  for (auto& f : a.Flush()) frames.push_back(std::move(f));
  EXPECT_EQ(a.stats().late_dropped, 1);
  EXPECT_EQ(a.stats().late_tracks, 1);
  ASSERT_EQ(frames.size(), 15u);
  EXPECT_FALSE(frames[12].tracks);
  ASSERT_TRUE(frames[13].tracks);
  EXPECT_EQ(frames[13].tracks->utime, 1'000'000 + 13 * kPeriod);
}

// The blue path of a track is the positions the tracker reported before, within trail_s.
TEST(FrameAssemblerTest, TrailsAreTheEarlierReportedPositions) {
  AssemblerParams p = Params(AssemblerParams::Trigger::kTracks);
  p.trail_s = 0.35;
  FrameAssembler a(p);
  std::vector<FrameInputs> frames;
  auto position = [](int k) { return Eigen::Vector2d(2.0 * k, 0.5 * k * k); };
  for (int k = 0; k < 10; ++k) {
    const std::int64_t t = 2'000'000 + k * kPeriod;
    const Eigen::Vector2d xy = position(k);
    a.AddTracks(Share(TrackList(t, k, {TrackAt(42, xy.x(), xy.y(), 0.0)})));
    for (auto& f : a.TakeReady()) frames.push_back(std::move(f));
  }
  for (auto& f : a.Flush()) frames.push_back(std::move(f));
  ASSERT_EQ(frames.size(), 10u);
  SceneBuilder builder(TwoDimensional());
  for (int k = 0; k < 10; ++k) {
    const Scene s = builder.Build(frames[static_cast<std::size_t>(k)]);
    ASSERT_EQ(s.tracks.size(), 1u);
    const auto& past = s.tracks[0].past;
    const int first = std::max(0, k - 3);  // 0.3 s back is inside 0.35 s, 0.4 s is not
    ASSERT_EQ(past.size(), static_cast<std::size_t>(k - first)) << k;
    for (int j = first; j < k; ++j) {
      EXPECT_EQ(past[static_cast<std::size_t>(j - first)], position(j)) << k << " " << j;
    }
    EXPECT_EQ(s.tracks[0].box.center, position(k));
  }
}

// Offline the whole true path is known: a frame shows it from trail_s before to truth_ahead_s
// after its time.
TEST(FrameAssemblerTest, KnownTruthPathAroundTheFrameTime) {
  AssemblerParams p = Params(AssemblerParams::Trigger::kTracks);
  p.trail_s = 1.0;
  p.truth_ahead_s = 2.0;
  FrameAssembler a(p);
  TimedPath path;
  for (int k = 0; k < 100; ++k) path.emplace_back(k * kPeriod, Eigen::Vector2d(k, -k));
  a.SetTruthPaths({{7, path}});
  const std::int64_t t = 5'000'000;
  a.AddTruth(Share(TruthAt(t, 50, 7, 50.0, -50.0, 0.0)));
  a.AddTracks(Share(TrackList(t, 50, {})));
  const auto frames = a.Flush();
  ASSERT_EQ(frames.size(), 1u);
  SceneBuilder builder(TwoDimensional());
  const Scene s = builder.Build(frames[0]);
  ASSERT_EQ(s.truths.size(), 1u);
  const auto& g = s.truths[0];
  EXPECT_EQ(g.id, 7);
  EXPECT_EQ(g.box.center, Eigen::Vector2d(50.0, -50.0));
  ASSERT_EQ(g.path.size(), 31u);  // k = 40 .. 70
  EXPECT_EQ(g.path.front(), Eigen::Vector2d(40.0, -40.0));
  EXPECT_EQ(g.path.back(), Eigen::Vector2d(70.0, -70.0));
}

TEST(FrameAssemblerTest, TimeGoingBackResetsAfterHandingOutWhatWasPending) {
  FrameAssembler a(Params(AssemblerParams::Trigger::kScans));
  for (int k = 0; k < 5; ++k) a.AddScan(Share(EmptyScan(50'000'000 + k * kPeriod, k)));
  a.AddScan(Share(EmptyScan(1'000'000, 0)));  // a replayed log started again
  const auto frames = a.TakeReady();
  EXPECT_EQ(a.stats().resets, 1);
  // The five frames of the first run, in order; the new run's first frame is still pending.
  ASSERT_EQ(frames.size(), 5u);
  EXPECT_EQ(frames.back().utime, 50'000'000 + 4 * kPeriod);
  const auto rest = a.Flush();
  ASSERT_EQ(rest.size(), 1u);
  EXPECT_EQ(rest[0].utime, 1'000'000);
  EXPECT_EQ(rest[0].time_origin_utime, 1'000'000);
}

TEST(FrameAssemblerTest, BadPosesAreRefusedAndCounted) {
  FrameAssembler a(Params(AssemblerParams::Trigger::kScans));
  const EgoArc ego;
  vtrack::pose_t p = ego.Pose(ego.t0);
  a.AddPose(p);
  a.AddPose(p);  // repeated
  vtrack::pose_t zero_q = ego.Pose(ego.t0 + 10'000);
  for (double& q : zero_q.orientation) q = 0.0;
  a.AddPose(zero_q);
  vtrack::pose_t nan_pos = ego.Pose(ego.t0 + 20'000);
  nan_pos.pos[0] = std::nan("");
  a.AddPose(nan_pos);
  EXPECT_EQ(a.stats().poses_refused, 3);
}

TEST(SceneBuilderTest, DebugEntriesBecomeMeasurementsOfTheirTracks) {
  const auto list = TrackList(3'000'000, 9, {TrackAt(5, 10.0, 20.0, 0.3), TrackAt(6, -4.0, 2.0, 1.0)});
  FrameAssembler a(Params(AssemblerParams::Trigger::kTracks));
  a.AddTracks(Share(list));
  a.AddDebug(Share(DebugFor(list)));
  const auto frames = a.Flush();
  ASSERT_EQ(frames.size(), 1u);
  SceneBuilder builder(TwoDimensional());
  const Scene s = builder.Build(frames[0]);
  EXPECT_EQ(s.mode, "mht");
  EXPECT_DOUBLE_EQ(s.latency_ms, 2.5);
  EXPECT_EQ(s.scan_seq, 9);
  ASSERT_EQ(s.measurements.size(), 2u);
  EXPECT_EQ(s.measurements[1].track_id, 6);
  EXPECT_NEAR((s.measurements[1].z_box.center - Eigen::Vector2d(-3.9, 1.95)).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.measurements[1].z_box.length, 4.5);
  ASSERT_EQ(s.measurements[1].edges.size(), 1u);
  EXPECT_EQ(s.measurements[1].edges[0].first, Eigen::Vector2d(-6.0, 1.0));
  EXPECT_FALSE(s.measurements[1].rear_axle.has_value());
}

TEST(MsgConvertTest, TrackFieldsAndRowMajorCovariance) {
  vtrack::track_t m = TrackAt(11, 1.0, 2.0, 0.5);
  for (int i = 0; i < 9; ++i) m.cov[i] = i + 1.0;
  m.status = vtrack::track_t::STATUS_COASTING;
  m.model = vtrack::track_t::MODEL_ISM;
  m.object_class = vtrack::track_t::CLASS_OTHER;
  m.npred = 2;
  m.pred_t = {0.5f, 1.0f};
  m.pred_x = {3.0, 4.0};
  m.pred_y = {5.0, 6.0};
  m.pred_theta = {0.5f, 0.5f};
  m.pred_pos_std = {0.1f, 0.2f};
  const SceneTrack t = TrackFromMsg(m);
  EXPECT_EQ(t.cov(0, 1), 2.0);  // row 0, column 1
  EXPECT_EQ(t.cov(1, 0), 4.0);
  EXPECT_EQ(t.cov(2, 1), 8.0);
  EXPECT_EQ(t.status, TrackStatus::kCoasting);
  EXPECT_EQ(t.model, MotionModel::kIsm);
  EXPECT_EQ(t.object_class, TrackClass::kOther);
  ASSERT_EQ(t.predicted.size(), 2u);
  EXPECT_EQ(t.predicted[1], Eigen::Vector2d(4.0, 6.0));
  EXPECT_DOUBLE_EQ(t.box.length, 4.5);
  EXPECT_DOUBLE_EQ(t.rear_axle_offset, -1.2);
}

TEST(MsgConvertTest, BadQuaternionsAreRefusedWithTheValues) {
  vtrack::pose_t p = EgoArc{}.Pose(0);
  p.orientation[0] = 2.0;
  std::string why;
  EXPECT_FALSE(PoseFromMsg(p, &why));
  EXPECT_NE(why.find("(2,"), std::string::npos) << why;
  vtrack::ladar_scan_t s = EmptyScan(0, 0);
  s.sensor_orientation[0] = s.sensor_orientation[1] = s.sensor_orientation[2] =
      s.sensor_orientation[3] = 0.0;
  EXPECT_FALSE(ScanFromMsg(s, &why));
  EXPECT_NE(why.find("sensor_orientation"), std::string::npos) << why;
  // A scan that cannot be placed is left out of the scene with a note, not a crash.
  FrameAssembler a(Params(AssemblerParams::Trigger::kScans));
  a.AddScan(Share(s));
  SceneBuilder builder(TwoDimensional());
  const Scene scene = builder.Build(a.Flush().at(0));
  EXPECT_TRUE(scene.points.empty());
  ASSERT_FALSE(scene.notes.empty());
}

TEST(FrameAssemblerTest, ParametersAreValidatedWithKeyAndValue) {
  AssemblerParams p;
  p.lag_us = -5;
  std::string error;
  EXPECT_FALSE(p.Validate(&error));
  EXPECT_NE(error.find("lag_us = -5"), std::string::npos) << error;
  EXPECT_THROW(FrameAssembler{p}, std::invalid_argument);
  SceneParams s;
  s.ego_width = 0.0;
  EXPECT_FALSE(s.Validate(&error));
  EXPECT_NE(error.find("ego_width = 0"), std::string::npos) << error;
}

}  // namespace
}  // namespace vtrack::viewer
