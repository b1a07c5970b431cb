// The tracker's YAML configuration: config/tracker.yaml loads, validates and states exactly the
// built-in defaults (so the file documents them); bad files are refused naming file, key, value.
// And the LCM conversions carry every field.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "tests/support/test_env.h"
#include "tracker/config.h"
#include "tracker/lcm_convert.h"

namespace vtrack {
namespace {

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseTrackerParams(yaml, "test.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(TrackerConfigTest, ShippedFileLoadsAndStatesTheDefaults) {
  const TrackerParams p = LoadTrackerParams(testing::SourceDir() + "/config/tracker.yaml");
  const TrackerParams d;
  std::string error;
  EXPECT_TRUE(p.Validate(&error)) << error;
  EXPECT_EQ(p.manager.mode, d.manager.mode);
  EXPECT_EQ(p.manager.max_hypotheses, d.manager.max_hypotheses);
  ASSERT_EQ(p.manager.vasm_variants.size(), d.manager.vasm_variants.size());
  for (std::size_t i = 0; i < d.manager.vasm_variants.size(); ++i) {
    EXPECT_EQ(p.manager.vasm_variants[i].inside_fraction, d.manager.vasm_variants[i].inside_fraction);
    EXPECT_EQ(p.manager.vasm_variants[i].noise_scale, d.manager.vasm_variants[i].noise_scale);
  }
  EXPECT_EQ(p.manager.mover_scans, d.manager.mover_scans);
  EXPECT_EQ(p.manager.switch_margin, d.manager.switch_margin);
  EXPECT_EQ(p.manager.fit_contour_deg, d.manager.fit_contour_deg);
  EXPECT_EQ(p.manager.axis_swap_ratio, d.manager.axis_swap_ratio);
  EXPECT_EQ(p.segmentation.cell_size, d.segmentation.cell_size);
  EXPECT_EQ(p.segmentation.connectivity, d.segmentation.connectivity);
  EXPECT_EQ(p.preprocess.ground, d.preprocess.ground);
  EXPECT_EQ(p.preprocess.max_range, d.preprocess.max_range);
  EXPECT_EQ(p.association.miss_cost, d.association.miss_cost);
  EXPECT_EQ(p.input.max_pose_wait_us, d.input.max_pose_wait_us);
  EXPECT_EQ(p.fit.max_scoring_points, d.fit.max_scoring_points);
  EXPECT_EQ(p.vasm.epsilon_L, d.vasm.epsilon_L);
  EXPECT_EQ(p.vasm.initial_L, d.vasm.initial_L);
  EXPECT_EQ(p.vasm.initial_L_std, d.vasm.initial_L_std);
  EXPECT_EQ(p.fit.max_inlier_gap_m, d.fit.max_inlier_gap_m);
  EXPECT_EQ(p.manager.contour_support_height, d.manager.contour_support_height);
  EXPECT_EQ(p.manager.contour_support_range, d.manager.contour_support_range);
  EXPECT_EQ(p.ism.alpha, d.ism.alpha);
  EXPECT_EQ(p.ekf.gate_probability, d.ekf.gate_probability);
  EXPECT_EQ(p.shape.half_life, d.shape.half_life);
}

TEST(TrackerConfigTest, OverridesAndPartialFiles) {
  const TrackerParams p = ParseTrackerParams(
      "manager:\n  mode: vasm\n  vasm_variants:\n    - {inside_fraction: 0.6, noise_scale: 2}\n"
      "    - {inside_fraction: 0.7, noise_scale: 1}\n    - {inside_fraction: 0.9, noise_scale: 3}\n"
      "preprocess:\n  ground: band\n",
      "inline");
  EXPECT_EQ(p.manager.mode, TrackerMode::kVasm);
  EXPECT_EQ(p.manager.vasm_variants[0].noise_scale, 2.0);
  EXPECT_EQ(p.preprocess.ground, PreprocessParams::Ground::kBand);
  EXPECT_EQ(p.segmentation.cell_size, SegmentationParams{}.cell_size);  // untouched default
  EXPECT_NO_THROW(ParseTrackerParams("", "empty"));
}

TEST(TrackerConfigTest, BadFilesNameFileKeyAndValue) {
  EXPECT_NE(ErrorOf("manager:\n  mode: kalman\n").find("test.yaml: manager.mode = 'kalman'"), std::string::npos);
  EXPECT_NE(ErrorOf("manager:\n  bogus: 1\n").find("manager.bogus is not a known key"), std::string::npos);
  EXPECT_NE(ErrorOf("nonsense: 1\n").find("nonsense is not a known section"), std::string::npos);
  EXPECT_NE(ErrorOf("preprocess:\n  max_range: far\n").find("preprocess.max_range = 'far'"), std::string::npos);
  EXPECT_NE(ErrorOf("preprocess:\n  max_range: -5\n").find("max_range = -5"), std::string::npos);
  EXPECT_NE(ErrorOf("segmentation:\n  connectivity: 6\n").find("connectivity = 6"), std::string::npos);
  EXPECT_NE(ErrorOf("manager: [1, 2]\n").find("manager is not a mapping"), std::string::npos);
  EXPECT_NE(ErrorOf("manager:\n  mode: [\n").find("not valid YAML"), std::string::npos);
  EXPECT_THROW(LoadTrackerParams("/nonexistent/tracker.yaml"), std::runtime_error);
}

TEST(LcmConvertTest, TrackReportCarriesEveryField) {
  TrackReport r;
  r.id = 42;
  r.status = TrackStatus::kCoasting;
  r.model = ModelKind::kVasm;
  r.moving = true;
  r.object_class = ObjectClass::kVehicle;
  r.x = 1.5; r.y = -2.5; r.theta = 0.3; r.speed = 4.0; r.velocity_heading = 0.35;
  r.yaw_rate = 0.1; r.rear_axle_offset = -1.3; r.length = 4.6; r.width = 1.9;
  r.cov << 1, 2, 3, 2, 5, 6, 3, 6, 9;
  r.num_hypotheses = 3; r.age = 2.5; r.num_updates = 20;
  for (int k = 0; k < 3; ++k) {
    PredictedPose p;
    p.t = 0.1 * k;
    p.pose = Eigen::Vector3d(k, 2.0 * k, 0.1 * k);
    p.pos_std = 0.2 + k;
    r.prediction.push_back(p);
  }
  const track_t t = TrackToLcm(r);
  EXPECT_EQ(t.id, 42);
  EXPECT_EQ(t.status, track_t::STATUS_COASTING);
  EXPECT_EQ(t.model, track_t::MODEL_VASM);
  EXPECT_TRUE(t.moving);
  EXPECT_EQ(t.object_class, track_t::CLASS_VEHICLE);
  EXPECT_EQ(t.x, 1.5); EXPECT_EQ(t.y, -2.5); EXPECT_EQ(t.theta, 0.3);
  EXPECT_EQ(t.rear_axle_offset, -1.3);
  EXPECT_EQ(t.cov[5], 6.0);  // row 1, column 2, row-major
  EXPECT_EQ(t.npred, 3);
  EXPECT_EQ(t.pred_y[2], 4.0);
  EXPECT_FLOAT_EQ(t.pred_pos_std[1], 1.2f);
  // A pose_t with a slightly non-unit quaternion is normalised; the scan arrays are moved.
  pose_t p{};
  p.orientation[0] = 1.0005;
  const EgoPose e = PoseFromLcm(p);
  EXPECT_NEAR((e.world_from_body.linear().transpose() * e.world_from_body.linear() -
               Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  ladar_scan_t s{};
  s.npoints = 2;
  s.x = {1, 2}; s.y = {3, 4}; s.z = {5, 6}; s.intensity = {0, 0}; s.dt_us = {7, 8}; s.ring = {0, 1};
  s.sensor_orientation[0] = 1.0;
  s.sensor_pos[2] = 1.7;
  const LadarScan ls = ScanFromLcm(std::move(s));
  EXPECT_EQ(ls.size(), 2u);
  EXPECT_EQ(ls.dt_us[1], 8);
  EXPECT_EQ(ls.body_from_sensor.translation().z(), 1.7);
}

}  // namespace
}  // namespace vtrack
