// vtrack-compare: its orchestration with stand-in tools whose results are known
// (fake_vtrack_tool.cc), and, when the real simulator and tracker are built, one real run.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "lcmtypes/util/log_reader.h"
#include "tests/sensor_driver/kitti_synthetic.h"
#include "tests/log_tools/synthetic_run.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "tests/support/tool_test.h"

namespace vtrack::testing {
namespace {

namespace fs = std::filesystem;

// A KITTI calibration for sequence seq in dir/calib: camera 2 looking along velo x, +-50 deg.
void WriteCalib(const std::string& dir, const std::string& seq) {
  fs::create_directories(dir + "/calib");
  std::ofstream c(dir + "/calib/" + seq + ".txt");
  const char* p = "500 0 600 0 0 500 180 0 0 0 1 0";
  c << "P0: " << p << "\nP1: " << p << "\nP2: " << p << "\nP3: " << p << "\n"
    << "R0_rect: 1 0 0 0 1 0 0 0 1\nTr_velo_to_cam: 0 -1 0 0 0 0 -1 0 1 0 0 0\n";
}

class CompareTest : public ToolTest {
 protected:
  CompareTest() : ToolTest("vtrack-compare", "compare") {}
  void Prepare() override {
    // The stand-in tools: links named like the real ones to the fake (built beside this test).
    const fs::path fake = fs::read_symlink("/proc/self/exe").parent_path() / "fake_vtrack_tool";
    ASSERT_TRUE(fs::exists(fake)) << fake;
    fake_bin_ = dir_ + "/bin";
    fs::create_directories(fake_bin_);
    for (const char* name : {"vtrack-sim-log", "vtrack-tracker", "vtrack-kitti2lcm"}) {
      fs::create_symlink(fake, fs::path(fake_bin_) / name);
    }
  }
  std::string fake_bin_;
};

TEST_F(CompareTest, HelpAndBadOptions) {
  std::string out;
  EXPECT_EQ(RunTool({"--help"}, &out), 0);
  EXPECT_NE(out.find("--scenarios"), std::string::npos);
  EXPECT_EQ(RunTool({}, &out), 2);
  EXPECT_NE(out.find("nothing to compare"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "a", "--modes", "ism,foo"}, &out), 2);
  EXPECT_NE(out.find("'foo'"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "a", "--gate", "-2"}, &out), 2);
  EXPECT_NE(out.find("gate_m"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "a", "--kitti-dontcare", dir_ + "/labels.txt"}, &out), 2);
  EXPECT_NE(out.find("--kitti-dontcare is not an option here"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "a", "--bin-dir", dir_ + "/nowhere"}, &out, {"TMPDIR=" + dir_}),
            1);
  EXPECT_NE(out.find("vtrack-sim-log"), std::string::npos) << out;
  // Outputs that cannot be written are said before any run, and leave no work directory.
  const std::string tmp = dir_ + "/tmp_outputs";
  fs::create_directories(tmp);
  EXPECT_EQ(RunTool({"--scenarios", "a", "--bin-dir", fake_bin_, "--json", dir_ + "/no/such/dir/c.json"},
                    &out, {"TMPDIR=" + tmp}), 1);
  EXPECT_NE(out.find("cannot write --json '" + dir_ + "/no/such/dir/c.json'"), std::string::npos) << out;
  EXPECT_EQ(out.find("[1/"), std::string::npos) << "a run started: " << out;
  std::ofstream(dir_ + "/a_file") << "x";
  EXPECT_EQ(RunTool({"--scenarios", "a", "--bin-dir", fake_bin_, "--plots", dir_ + "/a_file/plots"},
                    &out, {"TMPDIR=" + tmp}), 1);
  EXPECT_NE(out.find("cannot create --plots directory"), std::string::npos) << out;
  EXPECT_TRUE(fs::is_empty(tmp)) << "a temporary work directory was left in " << tmp;
  EXPECT_FALSE(fs::exists(dir_ + "/no"));
  // The check creates nothing: a --json through a link not yet pointing at a file stays a link.
  fs::remove(dir_ + "/link.json");
  fs::create_symlink("target.json", dir_ + "/link.json");
  EXPECT_EQ(RunTool({"--scenarios", "a", "--bin-dir", fake_bin_, "--json", dir_ + "/link.json",
                     "--plots", dir_ + "/a_file/plots"}, &out, {"TMPDIR=" + tmp}), 1);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir_ + "/link.json")));
  EXPECT_FALSE(fs::exists(dir_ + "/target.json"));
}

TEST_F(CompareTest, ThreeModesOnTwoScenariosAndKitti) {
  // A KITTI folder with a calibration.
  const std::string kitti = dir_ + "/kitti";
  WriteCalib(kitti, "0000");
  const std::string json = dir_ + "/cmp.json", plots = dir_ + "/plots", calls = dir_ + "/calls.txt";
  std::string out;
  ASSERT_EQ(RunTool({"--scenarios", "alpha,config/beta.yaml", "--kitti", kitti, "--bin-dir", fake_bin_,
                 "--json", json, "--plots", plots, "--seed", "7"},
                &out, {"FAKE_TOOL_LOG=" + calls}), 0) << out;
  // The table: a header, a rule and 3 x 3 rows.
  for (const char* s : {"alpha", "beta", "kitti_0000", "ism", "vasm", "mht", "MOTA", "HOTA"}) {
    EXPECT_NE(out.find(s), std::string::npos) << s << "\n" << out;
  }
  // The command lines of docs/design.md, section 8.
  const std::string c = ReadFile(calls);
  EXPECT_NE(c.find("vtrack-sim-log --scenario alpha --out run.lcm --seed 7"), std::string::npos) << c;
  EXPECT_NE(c.find("--mode mht --seed 7"), std::string::npos) << c;
  EXPECT_NE(c.find("vtrack-sim-log --scenario config/beta.yaml --out run.lcm"), std::string::npos) << c;
  EXPECT_NE(c.find("vtrack-kitti2lcm --kitti kitti --sequence 0000 --out run.lcm"), std::string::npos) << c;
  EXPECT_NE(c.find("vtrack-tracker --input run.lcm --output tracks_vasm.lcm --mode vasm"), std::string::npos) << c;

  const YAML::Node j = YAML::LoadFile(json);
  ASSERT_EQ(j.size(), 3u);
  // Scenarios: track 1 is off by the mode's offset, track 2 exact: position RMSE = offset / sqrt 2;
  // the tracker was given --seed 7, which the stand-in adds 6 x 0.02 m for.
  const std::map<std::string, double> offset = {{"ism", 0.62}, {"vasm", 0.42}, {"mht", 0.22}};
  for (const char* item : {"alpha", "beta"}) {
    for (const auto& [mode, off] : offset) {
      const YAML::Node s = j[item][mode];
      ASSERT_TRUE(s.IsMap()) << item << " " << mode;
      EXPECT_EQ(s["mode"].as<std::string>(), mode);
      EXPECT_NEAR(s["position_rmse_m"].as<double>(), off / std::sqrt(2.0), 1e-9) << item << mode;
      EXPECT_NEAR(s["mota"].as<double>(), 0.5, 1e-9);
      for (const char* key : {"motp_m", "id_switches", "fragmentations", "hota", "heading_rmse_deg",
                              "speed_rmse_mps", "nees_mean", "scans", "gt_objects"}) {
        EXPECT_TRUE(s[key].IsDefined()) << key;
      }
      EXPECT_TRUE(s["prediction_error_m"]["3"].IsDefined());
    }
  }
  // KITTI: scored in the camera view within 40 m, so the false positive behind the ego is dropped.
  EXPECT_EQ(j["kitti_0000"]["mht"]["false_positives"].as<int>(), 0);
  EXPECT_TRUE(j["kitti_0000"]["mht"]["params"]["region_camera"].as<bool>());
  EXPECT_NEAR(j["kitti_0000"]["mht"]["params"]["region_range_m"].as<double>(), 40.0, 1e-12);
  // The labels are half a sweep (of the fake's 100 ms) after the scan's utime.
  EXPECT_NEAR(j["kitti_0000"]["mht"]["params"]["truth_time_offset_s"].as<double>(), 0.05, 1e-12);
  EXPECT_NEAR(j["alpha"]["mht"]["params"]["truth_time_offset_s"].as<double>(), 0.0, 1e-12);

  for (const char* png : {"alpha_modes.png", "beta_modes.png", "kitti_0000_modes.png"}) {
    EXPECT_FALSE(cv::imread(plots + "/" + png).empty()) << png;
  }
}

// --kitti-input-modes: one item per input mode; the boxes item is converted without scans (its
// labels then share the frame's time: no half-sweep offset), the fused one tracked with both.
TEST_F(CompareTest, KittiInputModesGiveOneItemEach) {
  const std::string kitti = dir_ + "/kitti_modes";
  WriteCalib(kitti, "0000");
  const std::string json = dir_ + "/modes.json", calls = dir_ + "/modes_calls.txt";
  std::string out;
  EXPECT_EQ(RunTool({"--kitti", kitti, "--kitti-input-modes", "scans,lidar", "--bin-dir", fake_bin_},
                    &out), 2);
  EXPECT_NE(out.find("'lidar'"), std::string::npos) << out;
  ASSERT_EQ(RunTool({"--kitti", kitti, "--kitti-input-modes", "scans,boxes,fused", "--modes", "mht",
                     "--bin-dir", fake_bin_, "--json", json},
                    &out, {"FAKE_TOOL_LOG=" + calls}), 0) << out;
  const std::string c = ReadFile(calls);
  EXPECT_NE(c.find("--sequence 0000 --out run.lcm --no-scans"), std::string::npos) << c;
  EXPECT_NE(c.find("--mode mht --input-mode boxes"), std::string::npos) << c;
  EXPECT_NE(c.find("--mode mht --input-mode fused"), std::string::npos) << c;
  EXPECT_NE(c.find("--mode mht --input-mode scans"), std::string::npos) << c;
  const YAML::Node j = YAML::LoadFile(json);
  ASSERT_EQ(j.size(), 3u);
  EXPECT_NEAR(j["kitti_0000"]["mht"]["params"]["truth_time_offset_s"].as<double>(), 0.05, 1e-12);
  EXPECT_NEAR(j["kitti_0000_fused"]["mht"]["params"]["truth_time_offset_s"].as<double>(), 0.05, 1e-12);
  EXPECT_NEAR(j["kitti_0000_boxes"]["mht"]["params"]["truth_time_offset_s"].as<double>(), 0.0, 1e-12);
  // Without a label_02 file no DontCare regions; with one, every KITTI item is scored with them
  // unless --kitti-no-dontcare.
  EXPECT_FALSE(j["kitti_0000"]["mht"]["params"]["kitti_dont_care"].as<bool>());
  fs::create_directories(kitti + "/label_02");
  std::ofstream(kitti + "/label_02/0000.txt")
      << "0 -1 DontCare -1 -1 -10 100 100 200 200 -1 -1 -1 -1000 -1000 -1000 -10\n";
  for (const bool off : {false, true}) {
    std::vector<std::string> args = {"--kitti", kitti, "--kitti-input-modes", "scans,boxes",
                                     "--modes", "mht", "--bin-dir", fake_bin_, "--json", json};
    if (off) args.push_back("--kitti-no-dontcare");
    ASSERT_EQ(RunTool(args, &out, {"FAKE_TOOL_LOG=" + calls}), 0) << out;
    const YAML::Node k = YAML::LoadFile(json);
    EXPECT_EQ(k["kitti_0000"]["mht"]["params"]["kitti_dont_care"].as<bool>(), !off);
    EXPECT_EQ(k["kitti_0000_boxes"]["mht"]["params"]["kitti_dont_care"].as<bool>(), !off);
  }
}

// A folder of the same layout holding another sequence (a held-out kitti_tracking_NNNN) is scored
// by the same command: its own sequence is converted, calibrated and named; a folder with two
// sequences needs --kitti-sequence.
TEST_F(CompareTest, AKittiFolderOfAnotherSequenceIsScoredUnderItsOwnNumber) {
  const std::string kitti = dir_ + "/kitti_0007";
  WriteCalib(kitti, "0007");
  fs::create_directories(kitti + "/label_02");
  std::ofstream(kitti + "/label_02/0007.txt")
      << "0 -1 DontCare -1 -1 -10 100 100 200 200 -1 -1 -1 -1000 -1000 -1000 -10\n";
  const std::string json = dir_ + "/seq7.json", calls = dir_ + "/seq7_calls.txt";
  std::string out;
  ASSERT_EQ(RunTool({"--kitti", kitti, "--modes", "mht", "--bin-dir", fake_bin_, "--json", json},
                    &out, {"FAKE_TOOL_LOG=" + calls}), 0) << out;
  const std::string c = ReadFile(calls);
  EXPECT_NE(c.find("--sequence 0007 --out run.lcm"), std::string::npos) << c;
  // Scored with calib/0007.txt (without it the run stops) and label_02/0007.txt's DontCare.
  const YAML::Node j = YAML::LoadFile(json);
  ASSERT_TRUE(j["kitti_0007"]["mht"].IsMap());
  EXPECT_TRUE(j["kitti_0007"]["mht"]["params"]["kitti_dont_care"].as<bool>());
  EXPECT_FALSE(j["kitti_0000"].IsDefined());

  std::ofstream(kitti + "/calib/0008.txt") << "";
  EXPECT_EQ(RunTool({"--kitti", kitti, "--modes", "mht", "--bin-dir", fake_bin_}, &out), 2);
  EXPECT_NE(out.find("several sequences (0007, 0008)"), std::string::npos) << out;
  ASSERT_EQ(RunTool({"--kitti", kitti, "--kitti-sequence", "7", "--modes", "mht", "--bin-dir",
                     fake_bin_, "--json", json},
                    &out, {"FAKE_TOOL_LOG=" + calls}), 0) << out;
  EXPECT_TRUE(YAML::LoadFile(json)["kitti_0007"]["mht"].IsMap());
}

TEST_F(CompareTest, AFailedModeIsReportedAndTheRestStillScored) {
  const std::string json = dir_ + "/cmp.json";
  std::string out;
  // A failed run keeps its temporary work directory for inspection: here, inside the test's.
  EXPECT_EQ(RunTool({"--scenarios", "alpha,fail_sim", "--bin-dir", fake_bin_, "--json", json},
                &out, {"FAKE_TRACKER_FAIL_MODE=vasm", "TMPDIR=" + dir_}), 1) << out;
  EXPECT_NE(out.find("work directory kept: " + dir_ + "/vtrack-compare-"), std::string::npos)
      << out;
  EXPECT_NE(out.find("mode vasm fails"), std::string::npos) << out;          // the child's output
  EXPECT_NE(out.find("scenario fail_sim fails"), std::string::npos) << out;
  EXPECT_NE(out.find("failed"), std::string::npos) << out;                   // in the table
  const YAML::Node j = YAML::LoadFile(json);
  EXPECT_TRUE(j["alpha"]["ism"].IsMap());
  EXPECT_TRUE(j["alpha"]["vasm"].IsNull());
  EXPECT_TRUE(j["fail_sim"]["mht"].IsNull());
}

// --seeds: each scenario and each KITTI item measured by scans once per seed (its own item and
// work directory; the simulator's and the tracker's seed), then a row of the seeds' CLEAR MOT
// counts summed and their mean HOTA, after the item's last seed. Boxes alone: one run.
TEST_F(CompareTest, SeveralSeedsGiveOneItemEachAndTheirSum) {
  const std::string kitti = dir_ + "/kitti";
  WriteCalib(kitti, "0000");
  const std::string json = dir_ + "/cmp.json", calls = dir_ + "/calls.txt";
  std::string out;
  ASSERT_EQ(RunTool({"--scenarios", "alpha,beta", "--kitti", kitti, "--kitti-input-modes",
                     "scans,boxes", "--seeds", "3,5", "--modes", "ism,mht", "--bin-dir", fake_bin_,
                     "--json", json},
                    &out, {"FAKE_TOOL_LOG=" + calls}), 0) << out;
  const std::string c = ReadFile(calls);
  for (const char* call : {"vtrack-sim-log --scenario alpha --out run.lcm --seed 3",
                           "vtrack-sim-log --scenario alpha --out run.lcm --seed 5",
                           "vtrack-sim-log --scenario beta --out run.lcm --seed 5",
                           "vtrack-tracker --input run.lcm --output tracks_mht.lcm --mode mht --seed 5",
                           "--input-mode scans --seed 3"}) {
    EXPECT_NE(c.find(call), std::string::npos) << call << "\n" << c;
  }
  // The table (after the progress lines): alpha's seeds, then their sum, then beta's.
  const std::size_t table = out.find("-----");
  ASSERT_NE(table, std::string::npos) << out;
  const std::size_t a3 = out.find("alpha_seed3", table), a5 = out.find("alpha_seed5", table),
                    as = out.find("alpha_seeds", table), b3 = out.find("beta_seed3", table);
  ASSERT_NE(as, std::string::npos) << out;
  EXPECT_LT(a3, a5);
  EXPECT_LT(a5, as);
  EXPECT_LT(as, b3);
  const YAML::Node j = YAML::LoadFile(json);
  for (const char* mode : {"ism", "mht"}) {
    const YAML::Node s3 = j["alpha_seed3"][mode], s5 = j["alpha_seed5"][mode], sum = j["alpha_seeds"][mode];
    ASSERT_TRUE(s3.IsMap() && s5.IsMap() && sum.IsMap()) << mode;
    for (const char* key : {"gt_detections", "true_positives", "false_positives", "false_negatives",
                            "id_switches"}) {
      EXPECT_EQ(sum[key].as<int>(), s3[key].as<int>() + s5[key].as<int>()) << key;
    }
    const double gt = sum["gt_detections"].as<double>();
    ASSERT_GT(gt, 0.0);
    EXPECT_NEAR(sum["mota"].as<double>(),
                1.0 - (sum["false_negatives"].as<double>() + sum["false_positives"].as<double>() +
                       sum["id_switches"].as<double>()) / gt, 1e-12);
    // The stand-in tracks seed 5 0.04 m further off than seed 3: their localisation accuracies
    // differ (LocA, the mean HOTA similarity 1 - d / 2 m), the sum row has their mean.
    EXPECT_GT(s3["loca"].as<double>(), s5["loca"].as<double>() + 1e-3);
    for (const char* key : {"hota", "deta", "assa", "loca"}) {
      EXPECT_NEAR(sum[key].as<double>(), 0.5 * (s3[key].as<double>() + s5[key].as<double>()), 1e-8) << key;  // JSON: 9 digits
    }
  }
  EXPECT_EQ(c.find("--seed 1"), std::string::npos) << c;
  EXPECT_TRUE(j["beta_seeds"]["mht"].IsMap());
  EXPECT_FALSE(j["alpha"].IsDefined());
  for (const char* item : {"kitti_0000_seed3", "kitti_0000_seed5", "kitti_0000_seeds", "kitti_0000_boxes"}) {
    EXPECT_TRUE(j[item]["mht"].IsMap()) << item;
  }
  EXPECT_FALSE(j["kitti_0000_boxes_seed5"].IsDefined());
  // One seed keeps the scenario's own name; a seed given twice, or both options, is refused.
  EXPECT_EQ(RunTool({"--scenarios", "alpha", "--seeds", "4", "--modes", "mht", "--bin-dir", fake_bin_,
                     "--json", json}, &out), 0) << out;
  EXPECT_TRUE(YAML::LoadFile(json)["alpha"]["mht"].IsMap());
  EXPECT_EQ(RunTool({"--scenarios", "alpha", "--seeds", "4,4"}, &out), 2);
  EXPECT_NE(out.find("seed 4 given twice"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "alpha", "--seeds", "4,5", "--seed", "2"}, &out), 2);
  EXPECT_NE(out.find("--seed and --seeds"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "alpha", "--seeds", "4,z"}, &out), 2);
  EXPECT_NE(out.find("'z' is not an integer"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "alpha", "--seeds", "-1,2"}, &out), 2);
  EXPECT_NE(out.find("-1 must be >= 0"), std::string::npos) << out;
  EXPECT_EQ(RunTool({"--scenarios", "alpha", "--seeds", ""}, &out), 2);
  EXPECT_NE(out.find("--seeds is empty"), std::string::npos) << out;
  // A seed whose run fails leaves the sum row failed, not summed over the others.
  ASSERT_EQ(RunTool({"--scenarios", "alpha", "--seeds", "1,2", "--modes", "ism,vasm", "--bin-dir",
                     fake_bin_, "--json", json},
                    &out, {"FAKE_TRACKER_FAIL_MODE=vasm", "TMPDIR=" + dir_}), 1) << out;
  const YAML::Node f = YAML::LoadFile(json);
  EXPECT_TRUE(f["alpha_seeds"]["ism"].IsMap());
  EXPECT_TRUE(f["alpha_seeds"]["vasm"].IsNull());
}

TEST(CompareRealToolsTest, PaperScenarioThroughTheRealSimulatorAndTracker) {
  const std::string bin = BinDir();
  for (const char* tool : {"vtrack-compare", "vtrack-sim-log", "vtrack-tracker"}) {
    if (!fs::exists(bin + "/" + tool)) {
      GTEST_SKIP() << bin << "/" << tool << " is not built yet: the real-tool run of vtrack-compare "
                   << "needs the simulator and the tracker";
    }
  }
  const std::string scenario = SourceDir() + "/config/scenarios/paper_fig4_turn.yaml";
  if (!fs::exists(scenario)) GTEST_SKIP() << scenario << " does not exist yet";
  const std::string dir = ScratchDir("compare_real"), json = dir + "/cmp.json";
  const int rc = RunCommand({bin + "/vtrack-compare", "--scenarios", scenario, "--json", json,
                             "--work-dir", dir + "/work", "--quiet"},
                            dir + "/out.txt", std::chrono::minutes(5));
  ASSERT_EQ(rc, 0) << ReadFile(dir + "/out.txt");
  // The tracker answers every scan of a log it reads offline, so every ground-truth scan of the
  // simulator's log is scored, in every mode.
  int truth_scans = 0;
  vtrack::lcm_util::LogReader reader(dir + "/work/paper_fig4_turn/run.lcm");
  while (const lcm::LogEvent* ev = reader.Next()) truth_scans += ev->channel == "GROUND_TRUTH";
  ASSERT_GT(truth_scans, 0);
  const YAML::Node j = YAML::LoadFile(json);
  for (const char* mode : {"ism", "vasm", "mht"}) {
    const YAML::Node s = j["paper_fig4_turn"][mode];
    ASSERT_TRUE(s.IsMap()) << mode;
    EXPECT_EQ(s["mode"].as<std::string>(), mode);
    EXPECT_EQ(s["scans"].as<int>(), truth_scans) << mode;
    EXPECT_EQ(s["scans_without_tracks"].as<int>(), 0) << mode;
    EXPECT_GE(s["gt_objects"].as<int>(), 1) << mode;
    EXPECT_LE(s["mota"].as<double>(), 1.0) << mode;
    const double hota = s["hota"].as<double>();
    EXPECT_TRUE(hota >= 0.0 && hota <= 1.0) << mode << " " << hota;
  }
}


// A boxes-layout folder (kitti_tracking_boxes' layout: label_02, calib, ego_pose_orbslam3,
// detections/pointrcnn_Car) written here with known truth: two sequences of 30 frames, the ego
// standing still, each with two cars in camera 2's view (one driving away, one parked) and the
// detections equal to the labels plus seeded noise (5 cm, 1 deg).
void WriteBoxesSequence(const std::string& dir, const std::string& seq, unsigned seed,
                        int* label_rows) {
  for (const char* sub : {"label_02", "calib", "ego_pose_orbslam3", "detections/pointrcnn_Car"}) {
    fs::create_directories(dir + "/" + sub);
  }
  std::ofstream(dir + "/calib/" + seq + ".txt") << SyntheticSequence{}.CalibText();
  std::ofstream poses(dir + "/ego_pose_orbslam3/" + seq + ".txt");
  std::ofstream labels(dir + "/label_02/" + seq + ".txt");
  std::ofstream dets(dir + "/detections/pointrcnn_Car/" + seq + ".txt");
  std::mt19937 rng(seed);
  std::normal_distribution<double> pos(0.0, 0.05), head(0.0, 1.0 * M_PI / 180.0);
  // Rect frame: x right, y down (the ground 1.65 m below the camera), z forward. Heading along
  // +z is rotation_y = -pi/2.
  struct Car { int id; double x, z0, vz, ry; };
  const Car cars[] = {{0, -3.0, 10.0, 4.0, -M_PI / 2}, {1, 4.0, 22.0, 0.0, -M_PI / 2 + 0.2}};
  for (int i = 0; i < 30; ++i) {
    poses << "1 0 0 0 0 1 0 0 0 0 1 0\n";
    for (const Car& c : cars) {
      const double z = c.z0 + c.vz * 0.1 * i;
      char row[512];
      std::snprintf(row, sizeof(row), "%d %d Car 0 0 0 500 150 600 250 1.5 1.8 4.2 %.6f 1.65 %.6f %.6f\n",
                    i, c.id, c.x, z, c.ry);
      labels << row;
      ++*label_rows;
      std::snprintf(row, sizeof(row), "%d,2,500,150,600,250,8.5,1.5,1.8,4.2,%.6f,1.65,%.6f,%.6f,0\n", i,
                    c.x + pos(rng), z + pos(rng), c.ry + head(rng));
      dets << row;
    }
  }
}

TEST(CompareRealToolsTest, KittiBoxesTwoSequencesAndTheirSum) {
  const std::string bin = BinDir();
  for (const char* tool : {"vtrack-compare", "vtrack-kitti2lcm", "vtrack-tracker", "vtrack-eval",
                           "vtrack-eval-kitti"}) {
    if (!fs::exists(bin + "/" + tool)) GTEST_SKIP() << bin << "/" << tool << " is not built";
  }
  const std::string dir = ScratchDir("compare_kitti_boxes"), data = dir + "/boxes";
  int label_rows = 0;
  WriteBoxesSequence(data, "0001", 1, &label_rows);
  WriteBoxesSequence(data, "0002", 2, &label_rows);
  const std::string json = dir + "/cmp.json";
  const int rc = RunCommand({bin + "/vtrack-compare", "--kitti-boxes", data, "--modes", "cv,mht",
                             "--json", json, "--work-dir", dir + "/work", "--quiet"},
                            dir + "/out.txt", std::chrono::minutes(5));
  const std::string out = ReadFile(dir + "/out.txt");
  ASSERT_EQ(rc, 0) << out;
  for (const char* row : {"kitti_boxes_0001", "kitti_boxes_0002", "kitti_boxes_sum"}) {
    EXPECT_NE(out.find(row), std::string::npos) << row << " not in the table:\n" << out;
  }
  const YAML::Node j = YAML::LoadFile(json);
  for (const char* mode : {"cv", "mht"}) {
    SCOPED_TRACE(mode);
    int gt = 0, tp = 0;
    for (const char* item : {"kitti_boxes_0001", "kitti_boxes_0002"}) {
      const YAML::Node s = j[item][mode];
      ASSERT_TRUE(s.IsMap()) << item;
      // Two cars, 30 frames: every label is scored; the first frames before confirmation are
      // the only misses of clean detections.
      EXPECT_EQ(s["gt_detections"].as<int>(), 60) << item;
      EXPECT_GT(s["mota"].as<double>(), 0.85) << item;
      EXPECT_EQ(s["id_switches"].as<int>(), 0) << item;
      gt += s["gt_detections"].as<int>();
      tp += s["true_positives"].as<int>();
    }
    const YAML::Node sum = j["kitti_boxes_sum"][mode];
    ASSERT_TRUE(sum.IsMap());
    EXPECT_EQ(sum["gt_detections"].as<int>(), gt);
    EXPECT_EQ(sum["true_positives"].as<int>(), tp);
    EXPECT_GT(sum["mota"].as<double>(), 0.85);
    // The 3-D IoU criterion (vtrack-eval-kitti) over both sequences: every label counted, and
    // the tracks' scores (the detections' 8.5) let the sweep run.
    const YAML::Node iou = j["kitti_boxes_iou"][mode]["all"];
    ASSERT_TRUE(iou.IsMap());
    EXPECT_EQ(iou["gt"].as<int>(), label_rows);
    EXPECT_GT(iou["mota"].as<double>(), 0.85);
    EXPECT_EQ(iou["ids"].as<int>(), 0);
  }
}

}  // namespace
}  // namespace vtrack::testing
