// The tracker's YAML configuration: config/tracker.yaml loads, validates and states exactly the
// built-in defaults (so the file documents them); bad files are refused naming file, key, value.
// And the LCM conversions carry every field.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>

#include "sensor_driver/sim/scenario.h"
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

// Every field, through the one declaration list: the printed config of what the shipped file
// loads equals the printed built-in defaults key for key.
TEST(TrackerConfigTest, ShippedFileLoadsAndStatesTheDefaults) {
  const TrackerParams p = LoadTrackerParams(testing::SourceDir() + "/config/tracker.yaml");
  std::string error;
  EXPECT_TRUE(p.Validate(&error)) << error;
  std::ostringstream loaded, defaults;
  WriteConfigYaml(p, loaded);
  WriteConfigYaml(TrackerParams{}, defaults);
  EXPECT_EQ(loaded.str(), defaults.str());
  // Not vacuous: one changed field shows.
  TrackerParams changed;
  changed.shape.half_life += 1.0;
  std::ostringstream other;
  WriteConfigYaml(changed, other);
  EXPECT_NE(other.str(), defaults.str());
}

// Every scenario shipped beside it loads as well (the simulator's own reader refuses unknown and
// duplicate keys too).
TEST(TrackerConfigTest, EveryShippedScenarioLoads) {
  int loaded = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(testing::SourceDir() + "/config/scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    EXPECT_NO_THROW(sim::LoadScenario(entry.path().string(), 1.0)) << entry.path();
    ++loaded;
  }
  EXPECT_GE(loaded, 6);
}

TEST(TrackerConfigTest, DuplicateKeysEmptyFilesAndDirectoriesAreRefused) {
  const std::string twice = ErrorOf("association:\n  miss_cost: 3\n  gate_sigma: 2\n  miss_cost: -1\n");
  EXPECT_NE(twice.find("test.yaml: association.miss_cost appears twice (lines 2 and 4)"), std::string::npos)
      << twice;
  EXPECT_NE(ErrorOf("ism:\n  alpha: 1\nism:\n  beta: 1\n").find("ism appears twice"), std::string::npos);
  EXPECT_NE(ErrorOf("manager:\n  vasm_variants:\n    - {inside_fraction: 0.5, inside_fraction: 0.6}\n")
                .find("manager.vasm_variants[0].inside_fraction appears twice"),
            std::string::npos);
  EXPECT_NE(ErrorOf("").find("holds no section"), std::string::npos);
  EXPECT_NE(ErrorOf("# nothing but a comment\n").find("holds no section"), std::string::npos);
  const std::string dir = testing::ScratchDir("config_dir");
  try {
    LoadTrackerParams(dir);
    ADD_FAILURE() << "a directory was loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("is not a readable file (a directory)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadTrackerParams(dir + "/absent.yaml"), std::runtime_error);
}

// Each declared range is enforced on reading, naming file, key, value and the rule.
TEST(TrackerConfigTest, DeclaredRangesAreEnforced) {
  EXPECT_NE(ErrorOf("ekf:\n  gate_probability: 1\n").find("test.yaml: ekf.gate_probability = 1.0 -: must be in (0, 1)"),
            std::string::npos)
      << ErrorOf("ekf:\n  gate_probability: 1\n");
  EXPECT_NE(ErrorOf("manager:\n  vasm_variants:\n    - {inside_fraction: 2, noise_scale: 1}\n")
                .find("manager.vasm_variants[0].inside_fraction = 2.0 -: must be in [0, 1]"),
            std::string::npos);
  EXPECT_NE(ErrorOf("input:\n  max_queued_scans: 2.5\n").find("input.max_queued_scans = '2.5' is not a valid integer"),
            std::string::npos);
  // A value that is no number, as written: nothing, a list, a map.
  EXPECT_NE(ErrorOf("preprocess:\n  min_range:\n").find("preprocess.min_range = '' is not a valid number"),
            std::string::npos)
      << ErrorOf("preprocess:\n  min_range:\n");
  EXPECT_NE(ErrorOf("preprocess:\n  min_range: [1, 2]\n").find("preprocess.min_range = '[1, 2]' is not"),
            std::string::npos)
      << ErrorOf("preprocess:\n  min_range: [1, 2]\n");
  EXPECT_NE(ErrorOf("preprocess:\n  min_range: {a: 1}\n").find("preprocess.min_range = '{a: 1}' is not"),
            std::string::npos)
      << ErrorOf("preprocess:\n  min_range: {a: 1}\n");
  EXPECT_NE(ErrorOf("detections:\n  gate_m: 9\n").find("detections.gate_m = 9.0 m: must be <= max_gate_m"),
            std::string::npos);
  EXPECT_NE(ErrorOf("preprocess:\n  min_height: .nan\n").find("preprocess.min_height = nan m: must be finite"),
            std::string::npos);
}

// The evidence's tree lists: a node whose child lies before it or in another tree, a leaf with
// one child, a feature that does not exist, and a model whose list is empty are refused by name.
TEST(TrackerConfigTest, MalformedEvidenceTreesAreRefused) {
  const std::string two_trees =
      "evidence:\n  model_2d: trees\n  trees_2d:\n"
      "    - {tree: 0, feature: width, threshold: 1.0, left: 1, right: 2, value: 0}\n"
      "    - {tree: 0, feature: width, threshold: 0, left: -1, right: -1, value: 0.5}\n"
      "    - {tree: 0, feature: width, threshold: 0, left: -1, right: -1, value: -0.5}\n"
      "    - {tree: 1, feature: width, threshold: 0, left: -1, right: -1, value: 0.1}\n";
  const TrackerParams p = ParseTrackerParams(two_trees, "inline");
  ASSERT_EQ(p.evidence.trees_2d.size(), 4u);
  EXPECT_EQ(p.evidence.trees_2d[0].feature, EvidenceFeature::kWidth);
  auto with = [&](const std::string& from, const std::string& to) {
    std::string y = two_trees;
    y.replace(y.find(from), from.size(), to);
    return ErrorOf(y);
  };
  EXPECT_NE(with("left: 1, right: 2", "left: 1, right: 0").find("evidence.trees_2d[0].left/right = 0"),
            std::string::npos) << with("left: 1, right: 2", "left: 1, right: 0");
  EXPECT_NE(with("left: 1, right: 2", "left: 1, right: 3").find("trees_2d[0].left/right = 3"),
            std::string::npos);  // a node of tree 1
  EXPECT_NE(with("left: 1, right: 2", "left: 1, right: -1").find("trees_2d[0]: left and right"),
            std::string::npos);
  EXPECT_NE(with("feature: width, threshold: 1.0", "feature: colour, threshold: 1.0")
                .find("trees_2d[0].feature = 'colour'"),
            std::string::npos);
  EXPECT_NE(ErrorOf("evidence:\n  model_2d: trees\n  trees_2d: []\n").find("model_2d = trees: trees_2d is empty"),
            std::string::npos);
  EXPECT_NE(ErrorOf("evidence:\n  model_3d: logistic\n  terms_3d: []\n")
                .find("model_3d = logistic: terms_3d is empty"),
            std::string::npos);
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
  // An empty or comment-only file is refused (a config that sets nothing is a mistake).
  EXPECT_THROW(ParseTrackerParams("", "empty"), std::runtime_error);
  EXPECT_THROW(ParseTrackerParams("# only a comment\n", "comment"), std::runtime_error);
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
