// kitti::Sequence: on a synthetic sequence with known truth (standard layout, written by the
// test), and on the real KITTI sequence 0000 (skipped when ../shared/data is absent):
//   every labelled box in the world frame holds a point cluster, and the labelled parked cars
//   stay within 0.6 m of one world position.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "sensor_driver/kitti/kitti_sequence.h"
#include "tests/sensor_driver/kitti_synthetic.h"
#include "tests/support/test_env.h"
#include "base/angle.h"
#include "base/box.h"
#include "base/pose.h"
#include "vtrack/object_t.hpp"

namespace vtrack::kitti {
namespace {

using vtrack::testing::SyntheticObject;
using vtrack::testing::SyntheticSequence;

SyntheticSequence MakeSynthetic(const std::string& name) {
  SyntheticSequence s;
  s.dir = vtrack::testing::ScratchDir(name);
  s.num_frames = 6;
  SyntheticObject parked;  // ahead-left, parked
  parked.id = 3;
  parked.x0 = 14.0; parked.y0 = 3.0; parked.yaw0 = 0.3;
  SyntheticObject mover;   // ahead, driving and turning
  mover.id = 0;
  mover.type = "Van";
  mover.length = 5.0; mover.width = 2.0; mover.height = 2.2;
  mover.x0 = 22.0; mover.y0 = -3.0; mover.yaw0 = 0.1;
  mover.vx = 5.0; mover.vy = 1.0; mover.yaw_rate = 0.2;
  mover.points_inside = 12;
  SyntheticObject behind;  // behind the car: outside the camera's view
  behind.id = 5;
  behind.type = "Pedestrian";
  behind.length = 0.8; behind.width = 0.6; behind.height = 1.7;
  behind.x0 = -10.0; behind.y0 = 0.0;
  behind.first_frame = 2; behind.last_frame = 2;  // a lone label
  behind.points_inside = 7;
  s.objects = {parked, mover, behind};
  s.Write();
  return s;
}

SequenceOptions OptionsFor(const SyntheticSequence& s) {
  SequenceOptions o;
  o.dir = s.dir;
  o.sequence = "0";
  o.poses_file = s.dir + "/poses.txt";
  o.sink = [](const std::string&) {};
  return o;
}

TEST(KittiSequenceTest, SyntheticGroundTruthMatchesTheWorldTruth) {
  const SyntheticSequence s = MakeSynthetic("kitti_seq_truth");
  const Sequence seq(OptionsFor(s));
  ASSERT_EQ(seq.num_frames(), 6);
  ASSERT_TRUE(seq.has_labels());
  for (int i = 0; i < seq.num_frames(); ++i) {
    const double t = 0.1 * i;
    const auto gt = seq.GroundTruth(i);
    EXPECT_EQ(gt.utime, seq.ScanUtime(i));
    EXPECT_EQ(gt.scan_seq, i);
    EXPECT_EQ(gt.source, "kitti:0000");
    ASSERT_EQ(gt.num_objects, static_cast<int>(gt.objects.size()));
    ASSERT_EQ(gt.num_objects, i == 2 ? 3 : 2) << "frame " << i;  // DontCare rows are skipped
    for (const auto& o : gt.objects) {
      const SyntheticObject* truth = nullptr;
      for (const auto& so : s.objects) {
        if (so.id == o.id) truth = &so;
      }
      ASSERT_NE(truth, nullptr);
      EXPECT_NEAR(o.x, truth->X(t), 1e-9) << "id " << o.id;
      EXPECT_NEAR(o.y, truth->Y(t), 1e-9);
      EXPECT_NEAR(o.z, truth->bottom_z, 1e-9);
      EXPECT_NEAR(AngleDiff(o.yaw, truth->Yaw(t)), 0.0, 1e-9);
      EXPECT_DOUBLE_EQ(o.length, truth->length);
      EXPECT_DOUBLE_EQ(o.width, truth->width);
      EXPECT_DOUBLE_EQ(o.height, truth->height);
      EXPECT_EQ(o.num_points, truth->points_inside) << "id " << o.id << " frame " << i;
      EXPECT_TRUE(std::isnan(o.rear_axle_offset));
      if (o.id == 5) {
        // A single labelled frame: velocities are unknown; behind the camera: not labelled region.
        EXPECT_TRUE(std::isnan(o.vx));
        EXPECT_TRUE(std::isnan(o.yaw_rate));
        EXPECT_FALSE(o.in_labelled_region);
        EXPECT_FALSE(o.moving);
        EXPECT_EQ(o.object_class, vtrack::object_t::CLASS_PEDESTRIAN);
        continue;
      }
      // Linear motion: the least-squares slope is exact.
      EXPECT_NEAR(o.vx, truth->vx, 1e-6);
      EXPECT_NEAR(o.vy, truth->vy, 1e-6);
      EXPECT_NEAR(o.yaw_rate, truth->yaw_rate, 1e-6);
      EXPECT_NEAR(o.speed, truth->vx * std::cos(truth->Yaw(t)) + truth->vy * std::sin(truth->Yaw(t)), 1e-6);
      EXPECT_EQ(o.moving, o.id == 0);
      EXPECT_TRUE(o.in_labelled_region) << "id " << o.id;
    }
  }
}

TEST(KittiSequenceTest, SyntheticTimesAndPoses) {
  const SyntheticSequence s = MakeSynthetic("kitti_seq_pose");
  SequenceOptions o = OptionsFor(s);
  o.start_utime = 2'000'000'000'000'000;
  const Sequence seq(o);
  EXPECT_EQ(seq.FrameUtime(0), o.start_utime);
  EXPECT_EQ(seq.FrameUtime(3), o.start_utime + 300'000);
  EXPECT_EQ(seq.ScanUtime(3), o.start_utime + 250'000);
  const auto scan = seq.Scan(3);
  EXPECT_EQ(scan.utime, seq.ScanUtime(3));
  EXPECT_EQ(scan.seq, 3);
  for (int i = 0; i < seq.num_frames(); ++i) {
    const auto p = seq.EgoPose(i);
    EXPECT_EQ(p.utime, seq.FrameUtime(i));
    const Eigen::Isometry3d truth = s.WorldFromVelo(i);
    EXPECT_NEAR(p.pos[0], truth.translation().x(), 1e-9);
    EXPECT_NEAR(p.pos[1], truth.translation().y(), 1e-9);
    const Eigen::Quaterniond q(p.orientation[0], p.orientation[1], p.orientation[2], p.orientation[3]);
    EXPECT_NEAR(AngleDiff(YawOf(q), 0.05 * i), 0.0, 1e-9);
    // The ego moves 1.0 m, 0.2 m and turns 0.05 rad per 0.1 s frame.
    EXPECT_NEAR(p.vel[0], 10.0, 1e-6);
    EXPECT_NEAR(p.vel[1], 2.0, 1e-6);
    EXPECT_NEAR(p.rotation_rate[2], 0.5, 1e-6);
    EXPECT_NEAR(p.accel[0], 0.0, 1e-6);
    EXPECT_LT(p.pos_std[0], 0.0);
  }
  // Half-way between frames 1 and 2: the mid position and mid yaw.
  const auto mid = seq.PoseAt(seq.FrameUtime(1) + 50'000);
  EXPECT_NEAR(mid.pos[0], 1.5, 1e-9);
  EXPECT_NEAR(mid.pos[1], 0.3, 1e-9);
  // Before frame 0 (the first sweep's first half): extrapolated at constant velocity.
  const auto first = seq.PoseAt(seq.FirstPoseUtime());
  EXPECT_NEAR(first.pos[0], -0.5, 1e-9);
  EXPECT_THROW(seq.PoseAt(seq.FirstPoseUtime() - 1), KittiError);
  EXPECT_THROW(seq.PoseAt(seq.LastPoseUtime() + 1), KittiError);
  EXPECT_NO_THROW(seq.PoseAt(seq.LastPoseUtime()));
  EXPECT_THROW(seq.Scan(6), KittiError);
  EXPECT_THROW(seq.GroundTruth(-1), KittiError);
}

// Ego motion from an OXTS file: a vehicle driving north at 10 m/s with yaw = pi/2 (facing north).
TEST(KittiSequenceTest, SyntheticOxtsGivesVeloPoses) {
  SyntheticSequence s = MakeSynthetic("kitti_seq_oxts");
  std::filesystem::create_directories(s.dir + "/oxts");
  std::ofstream oxts(s.dir + "/oxts/0000.txt");
  constexpr double kR = 6378137.0;
  for (int i = 0; i < s.num_frames; ++i) {
    const double lat = 49.0 + (1.0 * i / kR) * 180.0 / M_PI;  // 1 m north per frame
    char b[512];
    std::snprintf(b, sizeof(b),
                  "%.15f 8.4 110 0 0 %.15f 0 10 10 0 0 0 0 9.8 0 0 9.8 0 0 0 0 0 0 0.02 0.01 4 10 4 4 0\n",
                  lat, M_PI / 2);
    oxts << b;
  }
  oxts.close();
  SequenceOptions o = OptionsFor(s);
  o.poses_file.clear();  // the default: DIR/oxts/0000.txt
  const Sequence seq(o);
  EXPECT_EQ(seq.paths().oxts_file, s.dir + "/oxts/0000.txt");
  // Tr_imu_to_velo of the synthetic calibration is a pure translation, so the Velodyne moves
  // exactly like the IMU: 1 m per frame along its own x (forward).
  for (int i = 0; i < s.num_frames; ++i) {
    const Eigen::Isometry3d& p = seq.WorldFromBody(i);
    EXPECT_NEAR(p.translation().x(), 1.0 * i, 1e-3);
    EXPECT_NEAR(p.translation().y(), 0.0, 1e-6);
    EXPECT_TRUE(p.linear().isApprox(Eigen::Matrix3d::Identity(), 1e-9));
  }
}

TEST(KittiSequenceTest, AFolderWithOneSequenceIsReadWithoutItsNumber) {
  // A folder of the same layout but another number (a held-out kitti_tracking_NNNN) is read as
  // it is: its only sequence with point clouds, whatever its number.
  const SyntheticSequence s = MakeSynthetic("kitti_seq_only_one");
  SequenceOptions o = OptionsFor(s);
  o.sequence.clear();
  const Sequence seq(o);
  EXPECT_EQ(seq.sequence(), "0000");
  EXPECT_EQ(seq.num_frames(), s.num_frames);

  namespace fs = std::filesystem;
  const fs::path d = vtrack::testing::ScratchDir("kitti_seq_listing");
  EXPECT_TRUE(PointCloudSequences(d.string()).empty());
  try {
    ResolveSequence(d.string(), "");
    ADD_FAILURE() << "a folder without point clouds has no sequence to resolve";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("no sequence in"), std::string::npos) << e.what();
  }
  // Packed archives, unpacked folders and the standard download's training/ all count; a name
  // that is not four digits does not.
  std::ofstream(d / "velodyne_0013.tar.zst") << "x";
  EXPECT_EQ(ResolveSequence(d.string(), ""), "0013");
  fs::create_directories(d / "training" / "velodyne" / "0004");
  fs::create_directories(d / "velodyne" / "13");
  std::ofstream(d / "velodyne_13.tar.zst") << "x";
  EXPECT_EQ(PointCloudSequences(d.string()), (std::vector<std::string>{"0004", "0013"}));
  try {
    ResolveSequence(d.string(), "");
    ADD_FAILURE() << "two sequences: the number must be given";
  } catch (const KittiError& e) {
    EXPECT_NE(std::string(e.what()).find("several sequences (0004, 0013)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ResolveSequence(d.string(), "4"), "0004");  // named: taken as given (normalised)
  EXPECT_EQ(ResolveSequence(d.string(), "0099"), "0099");  // located (or refused) later
}

TEST(KittiSequenceTest, ErrorsNameWhatIsMissingOrBad) {
  const SyntheticSequence s = MakeSynthetic("kitti_seq_bad");
  SequenceOptions o = OptionsFor(s);
  auto expect_error = [](const SequenceOptions& opt, const std::string& part) {
    try {
      Sequence seq(opt);
      ADD_FAILURE() << "expected an error mentioning " << part;
    } catch (const KittiError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  SequenceOptions bad = o;
  bad.dir = s.dir + "/nowhere";
  expect_error(bad, s.dir + "/nowhere");
  bad = o;
  bad.sequence = "0042";
  expect_error(bad, "sequence 0042 not found");
  bad = o;
  bad.sequence = "12a";
  expect_error(bad, "12a");
  bad = o;
  bad.oxts_file = s.dir + "/x.txt";
  expect_error(bad, "not both");
  bad = o;
  bad.moving_threshold_m = -1;
  expect_error(bad, "moving_threshold_m");
  bad = o;
  bad.poses_file.clear();
  expect_error(bad, "no ego motion");
  // Too few poses for the frames.
  {
    std::ofstream(s.dir + "/short_poses.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n";
    bad = o;
    bad.poses_file = s.dir + "/short_poses.txt";
    expect_error(bad, "has 1 poses but the sequence has 6 frames");
  }
  // A missing frame in the middle.
  std::filesystem::rename(s.dir + "/velodyne/0000/000003.bin", s.dir + "/velodyne/0000/x.bin");
  expect_error(o, "000003.bin is missing");
  std::filesystem::rename(s.dir + "/velodyne/0000/x.bin", s.dir + "/velodyne/0000/000003.bin");
  // A label for a frame the sequence does not have.
  {
    std::ofstream(s.dir + "/label_02/0000.txt", std::ios::app) << "9 1 Car 0 0 0 1 2 3 4 1.5 1.6 4 1 2 10 0\n";
    expect_error(o, "0000.txt:");
    expect_error(o, "frame 9");
  }
}

// ---------------------------------------------------------------------------------------------
// The real sequence.

class KittiRealTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string dir = vtrack::testing::KittiDir();
    if (dir.empty()) return;
    SequenceOptions o;
    o.dir = dir;
    o.cache_dir = vtrack::testing::BinDir() + "/../kitti_cache";
    seq_ = new Sequence(o);
  }
  static void TearDownTestSuite() {
    delete seq_;
    seq_ = nullptr;
  }
  void SetUp() override {
    if (!seq_) GTEST_SKIP() << "KITTI data not found (../shared/data/kitti_tracking_0000): skipped";
  }
  static Sequence* seq_;
};
Sequence* KittiRealTest::seq_ = nullptr;

TEST_F(KittiRealTest, SequenceShape) {
  EXPECT_EQ(seq_->num_frames(), 154);
  EXPECT_TRUE(seq_->has_labels());
  EXPECT_TRUE(seq_->paths().packed);
  EXPECT_NE(seq_->paths().poses_file.find("poses_velo_icp.txt"), std::string::npos);
}

// Counted independently of the library's rect-frame count: the scan's points mapped into the
// world with the frame's ego pose, tested against the world-frame rectangle and height band.
int CountInWorldBox(const vtrack::ladar_scan_t& scan, const Eigen::Isometry3d& world_from_body,
                    const vtrack::object_t& o) {
  OrientedBox box;
  box.center = Eigen::Vector2d(o.x, o.y);
  box.theta = o.yaw;
  box.length = o.length;
  box.width = o.width;
  int n = 0;
  for (int k = 0; k < scan.npoints; ++k) {
    const Eigen::Vector3d p = world_from_body * Eigen::Vector3d(scan.x[k], scan.y[k], scan.z[k]);
    if (p.z() >= o.z && p.z() <= o.z + o.height && box.Contains(p.head<2>())) ++n;
  }
  return n;
}

// README: at frames 0 and 153 every labelled box holds a cluster of 55-2000 points.
TEST_F(KittiRealTest, EveryLabelledBoxHoldsAPointCluster) {
  for (int frame : {0, 153}) {
    const auto scan = seq_->Scan(frame);
    const auto gt = seq_->GroundTruth(frame);
    ASSERT_GE(gt.num_objects, 3) << "frame " << frame;
    const Eigen::Isometry3d& world_from_body = seq_->WorldFromBody(frame);
    for (const auto& o : gt.objects) {
      const int independent = CountInWorldBox(scan, world_from_body, o);
      EXPECT_GE(independent, 50) << "frame " << frame << " id " << o.id;
      EXPECT_LE(independent, 2500) << "frame " << frame << " id " << o.id;
      // The library counts in the label's own (camera) frame: the two agree up to the ~1 deg tilt
      // between the camera and the world at the box edges.
      EXPECT_NEAR(o.num_points, independent, 0.05 * independent + 5) << "frame " << frame << " id " << o.id;
    }
  }
}

// README: tracks 3, 5-11, 13, 14 are parked cars and vans; tracks 0 (van) and 1 (cyclist) move.
TEST_F(KittiRealTest, ParkedCarsStayPutAndMoversMove) {
  const std::set<std::int64_t> parked = {3, 5, 6, 7, 8, 9, 10, 11, 13, 14};
  std::map<std::int64_t, std::vector<Eigen::Vector2d>> positions;
  std::map<std::int64_t, bool> moving;
  for (int i = 0; i < seq_->num_frames(); ++i) {
    // Positions and flags need no point counts: an empty frame skips reading the file.
    const auto gt = seq_->GroundTruth(i, VelodyneFrame{});
    for (const auto& o : gt.objects) {
      positions[o.id].push_back({o.x, o.y});
      moving[o.id] = o.moving;
    }
  }
  for (std::int64_t id : parked) {
    ASSERT_TRUE(positions.count(id)) << "track " << id;
    const auto& ps = positions[id];
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : ps) mean += p;
    mean /= static_cast<double>(ps.size());
    double worst = 0.0;
    for (const auto& p : ps) worst = std::max(worst, (p - mean).norm());
    EXPECT_LT(worst, 0.6) << "parked track " << id << " over " << ps.size() << " frames";
    EXPECT_FALSE(moving[id]) << "track " << id;
  }
  EXPECT_TRUE(moving[0]);
  EXPECT_TRUE(moving[1]);
  EXPECT_EQ(positions[0].size(), 154u);
  // The van ahead drives on: it covers several metres over the sequence.
  EXPECT_GT((positions[0].back() - positions[0].front()).norm(), 5.0);
}

// The box centre, projected with P2, falls inside the label's own 2-D image box for objects that
// are not truncated: an end-to-end check of calibration, frames and projection.
TEST_F(KittiRealTest, BoxCentresProjectIntoTheLabelledImageBoxes) {
  int checked = 0;
  for (const Label& l : seq_->labels()) {
    if (l.IsDontCare() || l.truncated > 0.0 || l.frame % 10 != 0) continue;
    const Eigen::Vector3d centre_rect = l.bottom_center_rect - Eigen::Vector3d(0, 0.5 * l.height, 0);
    const Eigen::Vector3d centre_velo = seq_->calibration().VeloFromRect() * centre_rect;
    const Eigen::Vector3d uvw = *seq_->calibration().P[2] * (seq_->calibration().RectFromVelo() * centre_velo).homogeneous();
    const double u = uvw.x() / uvw.z(), v = uvw.y() / uvw.z();
    EXPECT_GE(u, l.bbox[0] - 5) << "frame " << l.frame << " id " << l.track_id;
    EXPECT_LE(u, l.bbox[2] + 5);
    EXPECT_GE(v, l.bbox[1] - 5);
    EXPECT_LE(v, l.bbox[3] + 5);
    // Labelled region = the centre projects into the 1242 x 375 image (an edge band is excluded
    // from this check: a box at the image border may have its centre just outside).
    if (u > 10 && u < 1232 && v > 10 && v < 365) {
      EXPECT_TRUE(seq_->InLabelledRegionVelo(centre_velo)) << "frame " << l.frame << " id " << l.track_id;
    }
    EXPECT_FALSE(seq_->InLabelledRegionVelo(Eigen::Vector3d(-centre_velo.x(), centre_velo.y(), centre_velo.z())))
        << "mirrored behind the car";
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

// yaw = -rotation_y - pi/2 in the Velodyne frame (README), then rotated by the ego yaw.
TEST_F(KittiRealTest, YawFollowsTheReadmeRule) {
  for (int frame : {0, 80, 153}) {
    const auto gt = seq_->GroundTruth(frame, VelodyneFrame{});
    const double ego_yaw = YawOf(seq_->WorldFromBody(frame));
    for (const auto& o : gt.objects) {
      for (const Label& l : seq_->labels()) {
        if (l.frame != frame || l.track_id != o.id) continue;
        EXPECT_NEAR(AngleDiff(o.yaw, -l.rotation_y - kPi / 2 + ego_yaw), 0.0, 0.03)
            << "frame " << frame << " id " << o.id;
      }
    }
  }
}

TEST_F(KittiRealTest, EgoPoseIsContinuousAt100Hz) {
  // Interpolated poses between frames stay between the frame poses; velocities match the
  // displacement between frames.
  for (int i : {0, 50, 152}) {
    const auto a = seq_->EgoPose(i);
    const auto b = seq_->EgoPose(i + 1);
    const auto m = seq_->PoseAt(seq_->FrameUtime(i) + 50'000);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.pos[k], 0.5 * (a.pos[k] + b.pos[k]), 1e-9);
    const double speed = std::hypot(b.pos[0] - a.pos[0], b.pos[1] - a.pos[1]) / 0.1;
    EXPECT_NEAR(std::hypot(m.vel[0], m.vel[1]), speed, 0.5);
    EXPECT_LT(speed, 15.0);  // a residential street
  }
}

}  // namespace
}  // namespace vtrack::kitti
