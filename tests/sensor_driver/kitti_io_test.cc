// Parsers of the KITTI files on small hand-written files, and the calibration / OXTS transforms
// against computations written out by hand in the test.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "sensor_driver/kitti/kitti_io.h"
#include "tests/support/test_env.h"
#include "vtrack/object_t.hpp"

namespace vtrack::kitti {
namespace {

using vtrack::testing::ScratchDir;

std::string WriteText(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = dir + "/" + name;
  std::ofstream(path) << text;
  return path;
}

// Expects f() to throw KittiError whose message contains every one of `parts`.
template <class F>
void ExpectErrorMentions(F f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "expected a KittiError";
  } catch (const KittiError& e) {
    const std::string msg = e.what();
    for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  }
}

TEST(KittiVelodyneTest, ReadsFloat32Quadruples) {
  const std::string dir = ScratchDir("kitti_bin");
  const std::vector<float> raw = {1.5f, -2.25f, 0.125f, 0.5f, 10.0f, 20.0f, -1.0f, 0.99f};
  const std::string path = dir + "/000000.bin";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(raw.data()), 32);
  const VelodyneFrame f = ReadVelodyneBin(path);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f.x[0], 1.5f);
  EXPECT_EQ(f.y[0], -2.25f);
  EXPECT_EQ(f.z[0], 0.125f);
  EXPECT_EQ(f.reflectance[0], 0.5f);
  EXPECT_EQ(f.x[1], 10.0f);
  EXPECT_EQ(f.reflectance[1], 0.99f);
}

TEST(KittiVelodyneTest, RefusesTruncatedAndMissingFiles) {
  const std::string dir = ScratchDir("kitti_bin_bad");
  const std::string path = dir + "/000001.bin";
  std::ofstream(path, std::ios::binary) << std::string(17, '\0');
  ExpectErrorMentions([&] { ReadVelodyneBin(path); }, {path, "17 bytes", "multiple of 16"});
  ExpectErrorMentions([&] { ReadVelodyneBin(dir + "/nope.bin"); }, {dir + "/nope.bin"});
  ExpectErrorMentions([&] { ReadVelodyneBin(dir); }, {dir, "is a directory"});
}

// The tracking benchmark's spelling of the keys, with a tilted (not axis-aligned) calibration.
struct TiltedCalib {
  Eigen::Matrix3d r_cam_velo, r0;
  Eigen::Vector3d t_cam_velo{-0.0041, -0.0763, -0.2718};
  TiltedCalib() {
    // Axis permutation velo -> cam (x right = -y_velo, y down = -z_velo, z forward = x_velo),
    // followed by small rotations, like the real KITTI calibration.
    Eigen::Matrix3d perm;
    perm << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    r_cam_velo = Eigen::AngleAxisd(0.015, Eigen::Vector3d(0.3, 1.0, -0.2).normalized()).toRotationMatrix() * perm;
    r0 = Eigen::AngleAxisd(0.01, Eigen::Vector3d(-0.4, 0.8, 1.0).normalized()).toRotationMatrix();
  }
  static std::string Row(const Eigen::MatrixXd& m) {
    std::string s;
    char b[40];
    for (int r = 0; r < m.rows(); ++r) {
      for (int c = 0; c < m.cols(); ++c) {
        std::snprintf(b, sizeof(b), " %.17g", m(r, c));
        s += b;
      }
    }
    return s;
  }
  std::string Text(bool tracking_keys) const {
    Eigen::Matrix<double, 3, 4> tr;
    tr << r_cam_velo, t_cam_velo;
    Eigen::Matrix<double, 3, 4> p2;
    p2 << 721.5377, 0, 609.5593, 44.85728, 0, 721.5377, 172.854, 0.2163791, 0, 0, 1, 0.002745884;
    Eigen::Matrix<double, 3, 4> imu;
    imu << Eigen::Matrix3d::Identity(), Eigen::Vector3d(-0.81, 0.32, -0.80);
    if (tracking_keys) {
      return "P0:" + Row(p2) + "\nP1:" + Row(p2) + "\nP2:" + Row(p2) + "\nP3:" + Row(p2) +
             "\nR_rect" + Row(r0) + "\nTr_velo_cam" + Row(tr) + "\nTr_imu_velo" + Row(imu) + "\n";
    }
    return "P2:" + Row(p2) + "\nR0_rect:" + Row(r0) + "\nTr_velo_to_cam:" + Row(tr) +
           "\nTr_cam_to_road: 1 0 0 0 0 1 0 0 0 0 1 0\n";
  }
};

TEST(KittiCalibrationTest, BothKeySpellingsParse) {
  const std::string dir = ScratchDir("kitti_calib");
  const TiltedCalib tc;
  for (bool tracking_keys : {true, false}) {
    const Calibration c = ReadCalibration(WriteText(dir, "calib.txt", tc.Text(tracking_keys)));
    ASSERT_TRUE(c.P[2].has_value());
    EXPECT_DOUBLE_EQ((*c.P[2])(0, 0), 721.5377);
    EXPECT_DOUBLE_EQ((*c.P[2])(2, 3), 0.002745884);
    EXPECT_TRUE(c.R0_rect.isApprox(tc.r0, 1e-15));
    EXPECT_TRUE(c.cam_from_velo.linear().isApprox(tc.r_cam_velo, 1e-15));
    EXPECT_TRUE(c.cam_from_velo.translation().isApprox(tc.t_cam_velo, 1e-15));
    EXPECT_EQ(c.velo_from_imu.has_value(), tracking_keys);
    EXPECT_EQ(c.P[0].has_value(), tracking_keys);
  }
}

// A point built in the rectified camera frame, mapped to the Velodyne frame by the library and
// back by hand: X_rect = R0 (R X_velo + t)  =>  X_velo = R^T (R0^T X_rect - t).
TEST(KittiCalibrationTest, RectToVeloIsTheExactInverse) {
  const std::string dir = ScratchDir("kitti_calib_tf");
  const TiltedCalib tc;
  const Calibration c = ReadCalibration(WriteText(dir, "calib.txt", tc.Text(false)));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d x_rect(u(rng), u(rng), u(rng));
    const Eigen::Vector3d by_hand = tc.r_cam_velo.transpose() * (tc.r0.transpose() * x_rect - tc.t_cam_velo);
    EXPECT_LT((c.VeloFromRect() * x_rect - by_hand).norm(), 1e-12);
    EXPECT_LT((c.RectFromVelo() * by_hand - x_rect).norm(), 1e-12);
  }
  // A point 10 m straight ahead of the Velodyne is ~10 m along the camera's z (forward) axis.
  const Eigen::Vector3d ahead = c.RectFromVelo() * Eigen::Vector3d(10, 0, 0);
  EXPECT_NEAR(ahead.z(), 10.0 - 0.27, 0.2);
  EXPECT_NEAR(ahead.x(), 0.0, 0.2);
}

TEST(KittiCalibrationTest, ErrorsNameFileLineAndValue) {
  const std::string dir = ScratchDir("kitti_calib_bad");
  const TiltedCalib tc;
  std::string text = tc.Text(false);
  // A bad number on line 2 (R0_rect).
  const std::size_t at = text.find("R0_rect: ") + 9;
  const std::string bad = text.substr(0, at) + "x" + text.substr(at + 1);
  const std::string p1 = WriteText(dir, "bad_number.txt", bad);
  ExpectErrorMentions([&] { ReadCalibration(p1); }, {p1 + ":2", "R0_rect"});
  const std::string p2 = WriteText(dir, "no_p2.txt", text.substr(text.find('\n') + 1));
  ExpectErrorMentions([&] { ReadCalibration(p2); }, {p2, "missing calibration entry P2"});
  ExpectErrorMentions([&] { ReadCalibration(dir); }, {dir, "is a directory"});
  const std::string p3 = WriteText(dir, "short.txt", "P2: 1 0 0 0 0 1 0 0 0 0 1\nR0_rect: 1 0 0 0 1 0 0 0 1\n");
  ExpectErrorMentions([&] { ReadCalibration(p3); }, {p3 + ":1", "P2 has 11 values, expected 12"});
  const std::string p4 = WriteText(dir, "scaled.txt",
                                   "P2: 1 0 0 0 0 1 0 0 0 0 1 0\nR0_rect: 1 0 0 0 1 0 0 0 1\n"
                                   "Tr_velo_to_cam: 2 0 0 0 0 2 0 0 0 0 2 0\n");
  ExpectErrorMentions([&] { ReadCalibration(p4); }, {p4 + ":3", "not a rigid transform"});
  ExpectErrorMentions([&] { ReadCalibration(dir + "/missing.txt"); }, {dir + "/missing.txt"});
}

TEST(KittiLabelTest, ParsesRowsIncludingDontCare) {
  const std::string dir = ScratchDir("kitti_labels");
  const std::string path = WriteText(
      dir, "0000.txt",
      "0 -1 DontCare -1 -1 -10.000000 219.31 188.49 245.50 218.56 -1000 -1000 -1000 -10 -1 -1 -1\n"
      "0 0 Van 0 0 -1.793451 296.744956 161.752147 455.226042 292.372804 2.000000 1.823255 "
      "4.433886 -4.552284 1.858523 13.410495 -2.115488\n"
      "\n"
      "3 7 Pedestrian 0.5 2 0.1 1 2 3 4 1.7 0.6 0.8 1 2 3 0.25 0.93\n");
  const auto labels = ReadLabels(path);
  ASSERT_EQ(labels.size(), 3u);
  EXPECT_TRUE(labels[0].IsDontCare());
  EXPECT_EQ(labels[0].track_id, -1);
  EXPECT_EQ(labels[1].type, "Van");
  EXPECT_EQ(labels[1].track_id, 0);
  EXPECT_DOUBLE_EQ(labels[1].height, 2.0);
  EXPECT_DOUBLE_EQ(labels[1].width, 1.823255);
  EXPECT_DOUBLE_EQ(labels[1].length, 4.433886);
  EXPECT_DOUBLE_EQ(labels[1].bottom_center_rect.z(), 13.410495);
  EXPECT_DOUBLE_EQ(labels[1].rotation_y, -2.115488);
  EXPECT_DOUBLE_EQ(labels[1].bbox[3], 292.372804);
  EXPECT_EQ(labels[2].frame, 3);
  EXPECT_EQ(labels[2].occluded, 2);
  EXPECT_EQ(labels[2].line, 4);
  EXPECT_EQ(ClassOfType(labels[2].type), vtrack::object_t::CLASS_PEDESTRIAN);
  EXPECT_EQ(ClassOfType("Van"), vtrack::object_t::CLASS_VAN);
}

TEST(KittiLabelTest, ErrorsNameFileLineAndValue) {
  const std::string dir = ScratchDir("kitti_labels_bad");
  const std::string ok = "0 0 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 1 2 10 0.1\n";
  const std::string p1 = WriteText(dir, "type.txt", ok + "1 0 Spaceship 0 0 0 1 2 3 4 1.5 1.6 4.0 1 2 10 0.1\n");
  ExpectErrorMentions([&] { ReadLabels(p1); }, {p1 + ":2", "Spaceship"});
  const std::string p2 = WriteText(dir, "fields.txt", "0 0 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 1 2 10\n");
  ExpectErrorMentions([&] { ReadLabels(p2); }, {p2 + ":1", "got 16"});
  const std::string p3 = WriteText(dir, "number.txt", "0 0 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 1 2 1O 0.1\n");
  ExpectErrorMentions([&] { ReadLabels(p3); }, {p3 + ":1", "'1O'"});
  const std::string p4 = WriteText(dir, "dims.txt", "0 0 Car 0 0 0 1 2 3 4 1.5 -1.6 4.0 1 2 10 0.1\n");
  ExpectErrorMentions([&] { ReadLabels(p4); }, {p4 + ":1", "dimensions"});
  const std::string p5 = WriteText(dir, "id.txt", "0 -1 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 1 2 10 0.1\n");
  ExpectErrorMentions([&] { ReadLabels(p5); }, {p5 + ":1", "track_id -1"});
  const std::string p6 = WriteText(dir, "nan.txt", "0 0 Car 0 0 0 1 2 3 4 1.5 1.6 4.0 nan 2 10 0.1\n");
  ExpectErrorMentions([&] { ReadLabels(p6); }, {p6 + ":1", "'nan'"});
}

TEST(KittiPosesTest, ReadsRowMajorAndRefusesBadRotations) {
  const std::string dir = ScratchDir("kitti_poses");
  const double c = std::cos(0.3), s = std::sin(0.3);
  char line[256];
  std::snprintf(line, sizeof(line), "%.9f %.9f 0 1.5 %.9f %.9f 0 -2 0 0 1 0.25\n", c, -s, s, c);
  const std::string path = WriteText(dir, "poses.txt", std::string("1 0 0 0 0 1 0 0 0 0 1 0\n") + line);
  const auto poses = ReadPoses(path);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_TRUE(poses[0].isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(poses[1].translation().isApprox(Eigen::Vector3d(1.5, -2, 0.25)));
  // The point (1, 0, 0) of frame 1, in frame 0: rotated by 0.3 rad about z, then shifted.
  const Eigen::Vector3d p = poses[1] * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(p.x(), 1.5 + c, 1e-8);
  EXPECT_NEAR(p.y(), -2 + s, 1e-8);

  const std::string p1 = WriteText(dir, "scaled.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n2 0 0 0 0 2 0 0 0 0 2 0\n");
  ExpectErrorMentions([&] { ReadPoses(p1); }, {p1 + ":2", "not a rotation"});
  const std::string p2 = WriteText(dir, "short.txt", "1 0 0 0 0 1 0 0 0 0 1\n");
  ExpectErrorMentions([&] { ReadPoses(p2); }, {p2 + ":1", "got 11"});
  const std::string p3 = WriteText(dir, "empty.txt", "\n");
  ExpectErrorMentions([&] { ReadPoses(p3); }, {p3, "no poses"});
}

std::string OxtsLine(double lat, double lon, double alt, double roll, double pitch, double yaw) {
  char b[512];
  std::snprintf(b, sizeof(b),
                "%.12f %.12f %.6f %.9f %.9f %.9f 1 2 3 4 5 0.1 0.2 9.8 0.1 0.2 9.8 0.01 0.02 0.03 "
                "0.01 0.02 0.03 0.5 0.05 4 10 4 4 0\n",
                lat, lon, alt, roll, pitch, yaw);
  return b;
}

TEST(KittiOxtsTest, ParsesThirtyValuesAndNamesBadOnes) {
  const std::string dir = ScratchDir("kitti_oxts");
  const std::string path = WriteText(dir, "0000.txt", OxtsLine(49.0, 8.4, 110, 0.01, -0.02, 1.2));
  const auto recs = ReadOxts(path);
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_DOUBLE_EQ(recs[0].lat, 49.0);
  EXPECT_DOUBLE_EQ(recs[0].yaw, 1.2);
  EXPECT_DOUBLE_EQ(recs[0].az, 9.8);
  EXPECT_DOUBLE_EQ(recs[0].pos_accuracy, 0.5);
  EXPECT_EQ(recs[0].numsats, 10);
  const std::string good = OxtsLine(49.0, 8.4, 110, 0, 0, 0);
  const std::size_t at = good.find(" 1 2 3 ");
  const std::string bad = good.substr(0, at) + " v " + good.substr(at + 3);
  const std::string p1 = WriteText(dir, "bad.txt", OxtsLine(49.0, 8.4, 110, 0, 0, 0) + bad);
  ExpectErrorMentions([&] { ReadOxts(p1); }, {p1 + ":2", "vn", "'v'"});
  const std::string p2 = WriteText(dir, "lat.txt", OxtsLine(95.0, 8.4, 110, 0, 0, 0));
  ExpectErrorMentions([&] { ReadOxts(p2); }, {p2 + ":1", "latitude"});
  const std::string p3 = WriteText(dir, "few.txt", "49 8.4 110\n");
  ExpectErrorMentions([&] { ReadOxts(p3); }, {p3 + ":1", "got 3"});
}

// Mercator positions against spherical geometry: moving dlat north is R * dlat (meridian arc),
// moving dlon east along the parallel is R cos(lat) dlon (the devkit uses R = 6378137 m).
TEST(KittiOxtsTest, PosesMatchSphericalDistancesAndAttitude) {
  constexpr double kR = 6378137.0;
  const double lat0 = 49.0, lon0 = 8.4;
  const double dlat = 1e-3, dlon = 2e-3;  // [deg] ~111 m north, ~146 m east
  std::vector<OxtsRecord> recs(4);
  recs[0].lat = lat0; recs[0].lon = lon0; recs[0].alt = 100; recs[0].yaw = 0.4;
  recs[1] = recs[0]; recs[1].lat = lat0 + dlat;
  recs[2] = recs[0]; recs[2].lon = lon0 + dlon; recs[2].alt = 103;
  recs[3] = recs[0]; recs[3].yaw = 0.4 + 0.5; recs[3].roll = 0.1;
  const auto poses = OxtsToImuPoses(recs);
  ASSERT_EQ(poses.size(), 4u);
  EXPECT_TRUE(poses[0].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  // Positions are expressed in IMU frame 0, which is yawed by 0.4 rad from east.
  const Eigen::Matrix3d r0 = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d north = r0 * poses[1].translation();  // back to (east, north, up)
  EXPECT_NEAR(north.x(), 0.0, 1e-6);
  EXPECT_NEAR(north.y(), kR * dlat * M_PI / 180.0, 0.01);
  const Eigen::Vector3d east = r0 * poses[2].translation();
  EXPECT_NEAR(east.x(), kR * std::cos(lat0 * M_PI / 180.0) * dlon * M_PI / 180.0, 1e-6);
  EXPECT_NEAR(east.y(), 0.0, 1e-6);
  EXPECT_NEAR(east.z(), 3.0, 1e-9);
  // Record 3: yawed 0.5 rad more and rolled 0.1 rad: its y axis in frame 0 is the roll-tilted
  // left axis, rotated by 0.5 rad about z: (-sin 0.5 cos 0.1, cos 0.5 cos 0.1, sin 0.1).
  const Eigen::Vector3d y_axis = poses[3].linear() * Eigen::Vector3d::UnitY();
  EXPECT_LT((y_axis - Eigen::Vector3d(-std::sin(0.5) * std::cos(0.1), std::cos(0.5) * std::cos(0.1),
                                      std::sin(0.1))).norm(), 1e-12);
}

// An IMU turning in place by theta moves a Velodyne mounted at offset t on a circle:
// velo0_from_velo1 = (R(theta), t - R(theta) t) for velo_from_imu = pure translation t.
TEST(KittiOxtsTest, VeloPosesFollowTheLeverArm) {
  const Eigen::Vector3d t(-0.81, 0.32, -0.80);
  Eigen::Affine3d velo_from_imu = Eigen::Affine3d::Identity();
  velo_from_imu.translation() = t;
  const double theta = 0.7;
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const auto velo = ImuPosesToVeloPoses({Eigen::Isometry3d::Identity(), turn}, velo_from_imu);
  ASSERT_EQ(velo.size(), 2u);
  EXPECT_TRUE(velo[0].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  const Eigen::Vector3d expected = t - turn.linear() * t;
  EXPECT_LT((velo[1].translation() - expected).norm(), 1e-12);
  EXPECT_TRUE(velo[1].linear().isApprox(turn.linear(), 1e-12));
}

}  // namespace
}  // namespace vtrack::kitti
