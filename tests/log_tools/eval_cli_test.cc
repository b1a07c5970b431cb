// vtrack-eval as a process: options, exit codes, and its outputs (JSON read back with yaml-cpp,
// an independent parser; CSV; PNG files; the KITTI export checked against the calibration).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <numbers>
#include <limits>
#include <set>
#include <sstream>
#include <tuple>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "sensor_driver/kitti/kitti_io.h"
#include "tests/log_tools/synthetic_run.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "tests/support/tool_test.h"
#include "vtrack/track_list_t.hpp"

namespace vtrack::testing {
namespace {

// A KITTI calibration file with P0..P3 = [500 0 600 0; 0 500 180 0; 0 0 1 0], R0_rect = I and
// Tr_velo_to_cam the axis permutation (velo x forward, y left, z up -> cam x right, y down,
// z forward). Returns path.
std::string WriteAxisPermutationCalib(const std::string& path) {
  std::ofstream c(path);
  const char* p = "500 0 600 0 0 500 180 0 0 0 1 0";
  c << "P0: " << p << "\nP1: " << p << "\nP2: " << p << "\nP3: " << p << "\n"
    << "R0_rect: 1 0 0 0 1 0 0 0 1\n"
    << "Tr_velo_to_cam: 0 -1 0 0 0 0 -1 0 1 0 0 0\n"
    << "Tr_imu_to_velo: 1 0 0 0 0 1 0 0 0 0 1 0\n";
  return path;
}

// Copies the log in to out, each TRACKS message (the k-th, from 0) passed through edit.
void RewriteTracks(const std::string& in_path, const std::string& out_path,
                   const std::function<void(int, vtrack::track_list_t*)>& edit) {
  lcm_util::LogReader in(in_path);
  lcm_util::LogWriter w(out_path);
  int k = 0;
  while (const lcm::LogEvent* ev = in.Next()) {
    if (ev->channel != "TRACKS") {
      w.Write(ev->timestamp, ev->channel, ev->data, static_cast<std::size_t>(ev->datalen));
      continue;
    }
    vtrack::track_list_t m;
    ASSERT_EQ(lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &m),
              lcm_util::DecodeError::kNone);
    edit(k++, &m);
    w.WriteMessage(ev->timestamp, "TRACKS", m);
  }
}

class EvalCliTest : public ToolTest {
 protected:
  EvalCliTest() : ToolTest("vtrack-eval", "eval_cli") {}
  void Prepare() override {
    run_ = dir_ + "/run.lcm";
    tracks_ = dir_ + "/tracks.lcm";
    WriteSyntheticRun(run_);
    WriteSyntheticTracks(tracks_, "vasm");
  }
  std::string run_, tracks_;
};

TEST_F(EvalCliTest, HelpAndBadOptions) {
  std::string out;
  EXPECT_EQ(RunTool({"--help"}, &out), 0);
  EXPECT_NE(out.find("--json"), std::string::npos);
  EXPECT_NE(out.find("--kitti-out"), std::string::npos);
  EXPECT_EQ(RunTool({}, &out), 2);
  EXPECT_NE(out.find("no LOG"), std::string::npos) << out;
  EXPECT_EQ(RunTool({run_, "--gate", "0"}, &out), 2);
  EXPECT_NE(out.find("gate_m must be > 0, got 0"), std::string::npos) << out;
  EXPECT_EQ(RunTool({run_, "--horizons", "1,x"}, &out), 2);
  EXPECT_NE(out.find("'x'"), std::string::npos) << out;
  EXPECT_EQ(RunTool({run_, "--region-camera"}, &out), 2);
  EXPECT_NE(out.find("--kitti-calib"), std::string::npos) << out;
  EXPECT_EQ(RunTool({run_, "--kitti-dontcare", dir_ + "/labels.txt"}, &out), 2);
  EXPECT_NE(out.find("--kitti-dontcare needs --region-camera"), std::string::npos) << out;
  // A missing label file, and a DontCare box whose corners are swapped: refused, named.
  const std::string calib = WriteAxisPermutationCalib(dir_ + "/calib_bad.txt");
  EXPECT_EQ(RunTool({run_, tracks_, "--region-camera", "--kitti-calib", calib, "--kitti-dontcare",
                     dir_ + "/no_labels.txt"}, &out), 2);
  EXPECT_NE(out.find("no_labels.txt"), std::string::npos) << out;
  const std::string swapped = dir_ + "/swapped.txt";
  std::ofstream(swapped) << "0 -1 DontCare -1 -1 -10 300 100 200 200 -1 -1 -1 -1000 -1000 -1000 -10\n";
  EXPECT_EQ(RunTool({run_, tracks_, "--region-camera", "--kitti-calib", calib, "--kitti-dontcare",
                     swapped}, &out), 2);
  EXPECT_NE(out.find("swapped.txt:1: DontCare box with x2 < x1"), std::string::npos) << out;
  EXPECT_EQ(RunTool({dir_ + "/missing.lcm"}, &out), 1);
  EXPECT_NE(out.find("missing.lcm"), std::string::npos) << out;
  EXPECT_EQ(RunTool({run_}, &out), 1);  // no tracks in it
  EXPECT_NE(out.find("no tracks"), std::string::npos) << out;
  // Ground truth whose every message is damaged: there, but unreadable, and said so.
  const std::string damaged = dir_ + "/damaged_truth.lcm";
  {
    lcm_util::LogWriter w(damaged);
    for (int k = 0; k < 3; ++k) w.Write(1000 * k, "GROUND_TRUTH", "not an object list", 18);
  }
  EXPECT_EQ(RunTool({damaged, tracks_}, &out), 1);
  EXPECT_NE(out.find("no ground truth (object_list_t on channel 'GROUND_TRUTH') in the logs: 3 "
                     "messages on it could not be decoded"), std::string::npos) << out;
}

TEST_F(EvalCliTest, WritesJsonCsvAndPlots) {
  const std::string json = dir_ + "/m.json", csv = dir_ + "/t.csv", plots = dir_ + "/plots";
  std::string out;
  ASSERT_EQ(RunTool({run_, tracks_, "--json", json, "--csv", csv, "--plots", plots}, &out), 0) << out;
  EXPECT_NE(out.find("MOTA 0.500"), std::string::npos) << out;

  const YAML::Node j = YAML::LoadFile(json);
  for (const char* key : {"mota", "motp_m", "id_switches", "fragmentations", "hota",
                          "position_rmse_m", "heading_rmse_deg", "speed_rmse_mps",
                          "prediction_error_m", "nees_mean", "scans", "gt_objects"}) {
    EXPECT_TRUE(j[key].IsDefined()) << key;
  }
  EXPECT_EQ(j["mode"].as<std::string>(), "vasm");
  EXPECT_NEAR(j["mota"].as<double>(), 0.5, 1e-9);
  EXPECT_EQ(j["scans"].as<int>(), kScans);
  EXPECT_EQ(j["gt_objects"].as<int>(), 2);
  EXPECT_EQ(j["id_switches"].as<int>(), 0);
  for (const char* h : {"1", "2", "3"}) {
    EXPECT_NEAR(j["prediction_error_m"][h].as<double>(), 1.0, 1e-6) << h;
  }
  EXPECT_NEAR(j["nees_mean"].as<double>(), 1.0, 1e-6);

  // CSV: a header and one row per scored track (1, 2, 7).
  std::ifstream in(csv);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0].rfind("track_id,", 0), 0u);
  EXPECT_EQ(lines[1].rfind("1,", 0), 0u);
  EXPECT_EQ(lines[3].rfind("7,", 0), 0u);

  for (const char* png : {"errors_over_time.png", "detections_over_time.png", "prediction_error.png"}) {
    const cv::Mat img = cv::imread(plots + "/" + png);
    EXPECT_FALSE(img.empty()) << png;
    EXPECT_GT(img.cols, 300) << png;
  }
}

TEST_F(EvalCliTest, TrackLabelsFileLeavesTheScoresAlone) {
  const std::string plain = dir_ + "/plain.json", json = dir_ + "/l.json", labels = dir_ + "/l.csv";
  std::string out;
  ASSERT_EQ(RunTool({run_, tracks_, "-q", "--json", plain}, &out), 0) << out;
  ASSERT_EQ(RunTool({run_, tracks_, "-q", "--json", json, "--track-labels", labels}, &out), 0) << out;
  EXPECT_NE(out.find("wrote " + labels), std::string::npos) << out;
  auto slurp = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  EXPECT_EQ(slurp(plain), slurp(json));
  // Every track (1..7, any status and class) of each of the kScans frames with truth (the track
  // list at +100 s has none): labels by synthetic_run.h.
  std::ifstream in(labels);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "utime,track_id,label,range_m,truth_id,truth_class,distance_m");
  int rows = 0;
  std::int64_t last_utime = 0;
  while (std::getline(in, line)) {
    ++rows;
    std::vector<std::string> f;
    std::istringstream fields(line);
    for (std::string x; std::getline(fields, x, ',');) f.push_back(x);
    ASSERT_EQ(f.size(), 7u) << line;
    const std::int64_t utime = std::stoll(f[0]);
    EXPECT_GE(utime, last_utime);
    EXPECT_LT(utime, kUtime0 + kScans * 100'000);
    last_utime = utime;
    const int id = std::stoi(f[1]);
    const std::string label_truth = f[2] + "," + f[4] + "," + f[5];
    if (id == 1 || id == 2) {  // cars A, B
      EXPECT_EQ(label_truth, "1," + f[1] + ",1") << line;
    }
    if (id == 3) {  // other, far from everything
      EXPECT_EQ(label_truth, "0,-1,-1") << line;
    }
    if (id == 4) {  // on the pedestrian
      EXPECT_EQ(label_truth, "0,3,5") << line;
    }
    if (id == 5) {  // on the unlabelled car
      EXPECT_EQ(label_truth, "-1,4,1") << line;
    }
    if (id == 2) {
      EXPECT_NEAR(std::stod(f[6]), 0.0, 1e-9) << line;
    }
    if (id == 3) {  // ego at 0
      EXPECT_NEAR(std::stod(f[3]), std::hypot(50.0, 50.0), 1e-6) << line;
    }
  }
  EXPECT_EQ(rows, 7 * kScans);
}

TEST_F(EvalCliTest, KittiExportFollowsTheCalibration) {
  // A calibration with P2 = [500 0 600 0; 0 500 180 0; 0 0 1 0], R0_rect = I and
  // Tr_velo_to_cam the axis permutation (velo x forward, y left, z up -> cam x right, y down,
  // z forward). The world is the velo frame (the ego stays at the origin).
  const std::string calib = WriteAxisPermutationCalib(dir_ + "/calib.txt");
  const std::string out_file = dir_ + "/kitti.txt";
  std::string out;
  ASSERT_EQ(RunTool({run_, tracks_, "--kitti-calib", calib, "--kitti-out", out_file,
                 "--kitti-image-size", "1200x360"}, &out), 0) << out;
  std::ifstream in(out_file);
  int lines = 0, b_lines = 0;
  for (std::string l; std::getline(in, l);) {
    ++lines;
    std::istringstream ss(l);
    long long frame = 0, id = 0;
    std::string type;
    double trunc, occ, alpha, x1, y1, x2, y2, h, w, len, x, y, z, ry, score;
    ASSERT_TRUE(ss >> frame >> id >> type >> trunc >> occ >> alpha >> x1 >> y1 >> x2 >> y2 >> h >>
                w >> len >> x >> y >> z >> ry >> score) << l;
    EXPECT_EQ(type, "Car");
    EXPECT_TRUE(x1 >= 0 && x2 <= 1199 && x1 < x2 && y1 >= 0 && y2 <= 359 && y1 < y2) << l;
    EXPECT_NE(id, 3);  // CLASS_OTHER is not a vehicle
    EXPECT_NE(id, 6);  // tentative
    if (id == 2) {
      // Track 2: B at velo (10, -5), theta = 0.3 - pi (stationary, so the time advance does not
      // move it). Bottom centre: velo (10, -5, -1.73) -> cam (5, 1.73, 10). KITTI's relation
      // yaw_velo = -rotation_y - pi/2.
      ++b_lines;
      EXPECT_NEAR(x, 5.0, 1e-5);
      EXPECT_NEAR(y, 1.73, 1e-5);
      EXPECT_NEAR(z, 10.0, 1e-5);
      EXPECT_NEAR(std::remainder(-ry - std::numbers::pi / 2 - (0.3 - std::numbers::pi),
                                 2 * std::numbers::pi), 0.0, 1e-5);
      EXPECT_NEAR(std::remainder(alpha - (ry - std::atan2(x, z)), 2 * std::numbers::pi), 0.0, 1e-5);
      EXPECT_NEAR(h, 1.6, 1e-9);
      EXPECT_NEAR(w, 1.8, 1e-9);
      EXPECT_NEAR(len, 4.5, 1e-9);
    }
  }
  EXPECT_EQ(b_lines, kScans);  // the extra track list at +100 s has no ego pose
  EXPECT_NE(out.find("1 frames without pose"), std::string::npos) << out;
  EXPECT_GT(lines, b_lines);
  EXPECT_NE(out.find("states advanced 0.05 s"), std::string::npos) << out;  // half of 100 ms
}

// A track measured by a detector's boxes carries their bottom and height (track_t.z, height):
// the export places the box there instead of on the road. Track 2 of the synthetic tracks given
// z = -1.2 m (world = velo here: ego and sensor at the origin) and height 1.9 m: bottom centre
// velo (10, -5, -1.2) -> cam (5, 1.2, 10), h 1.9.
TEST_F(EvalCliTest, KittiExportTakesATracksBottomAndHeightFromItsBoxes) {
  const std::string calib = WriteAxisPermutationCalib(dir_ + "/calib_z.txt");
  const std::string tracks_z = dir_ + "/tracks_z.lcm";
  RewriteTracks(tracks_, tracks_z, [](int, vtrack::track_list_t* m) {
    for (auto& t : m->tracks) {
      if (t.id == 3) {  // classed other but measured by boxes: exported too
        t.z = -1.5;
        t.height = 1.4;
      }
      if (t.id != 2) continue;
      t.z = -1.2;
      t.height = 1.9;
    }
  });
  const std::string out_file = dir_ + "/kitti_z.txt";
  std::string out;
  ASSERT_EQ(RunTool({run_, tracks_z, "--kitti-calib", calib, "--kitti-out", out_file,
                     "--kitti-image-size", "1200x360"}, &out), 0) << out;
  std::ifstream in(out_file);
  int b_lines = 0, other_lines = 0, boxed_other_lines = 0;
  for (std::string l; std::getline(in, l);) {
    std::istringstream ss(l);
    long long frame = 0, id = 0;
    std::string type;
    double trunc, occ, alpha, x1, y1, x2, y2, h, w, len, x, y, z, ry, score;
    ASSERT_TRUE(ss >> frame >> id >> type >> trunc >> occ >> alpha >> x1 >> y1 >> x2 >> y2 >> h >>
                w >> len >> x >> y >> z >> ry >> score) << l;
    if (id == 2) {
      ++b_lines;
      EXPECT_NEAR(x, 5.0, 1e-5);
      EXPECT_NEAR(y, 1.2, 1e-5);
      EXPECT_NEAR(z, 10.0, 1e-5);
      EXPECT_NEAR(h, 1.9, 1e-9);
    } else if (id == 3) {
      ++boxed_other_lines;
      EXPECT_NEAR(h, 1.4, 1e-9) << l;
    } else {
      ++other_lines;
      EXPECT_NEAR(y, 1.73, 1e-5) << l;  // no box measured it: on the road
      EXPECT_NEAR(h, 1.6, 1e-9) << l;
    }
  }
  EXPECT_EQ(b_lines, kScans);
  EXPECT_GT(other_lines, 0);
  EXPECT_GT(boxed_other_lines, 0);  // a box track of low score: its class other, still exported
}


// Which tracks the KITTI export writes, by status: track 2 (in the camera's view) rewritten as a
// box track (height finite) whose status and update count follow a script, and track 8, a copy
// measured by scans only (no height) and tentative throughout. Expected frames counted by hand.
TEST_F(EvalCliTest, KittiExportWritesTentativeBoxTracksAndAShortCoast) {
  const std::string calib = WriteAxisPermutationCalib(dir_ + "/calib_s.txt");
  // Frame k: status and num_updates of track 2.
  //   0, 1: tentative, 1 and 2 updates (measured); 2: tentative, still 2 (missed); 3: tentative, 3;
  //   4-9: confirmed, 4-9; 10-13: coasting, 9; 14 on: confirmed, 10 on.
  const auto script = [](int k) -> std::pair<std::int8_t, std::int32_t> {
    using T = vtrack::track_t;
    if (k <= 1) return {T::STATUS_TENTATIVE, k + 1};
    if (k == 2) return {T::STATUS_TENTATIVE, 2};
    if (k == 3) return {T::STATUS_TENTATIVE, 3};
    if (k <= 9) return {T::STATUS_CONFIRMED, k};
    if (k <= 13) return {T::STATUS_COASTING, 9};
    return {T::STATUS_CONFIRMED, k - 4};
  };
  const std::string tracks_s = dir_ + "/tracks_s.lcm";
  RewriteTracks(tracks_, tracks_s, [&](int k, vtrack::track_list_t* m) {
    std::vector<vtrack::track_t> kept;
    for (auto t : m->tracks) {
      if (t.id != 2) continue;
      t.z = -1.2;
      t.height = 1.9;
      std::tie(t.status, t.num_updates) = script(k);
      kept.push_back(t);
      vtrack::track_t scan_only = t;
      scan_only.id = 8;
      scan_only.status = vtrack::track_t::STATUS_TENTATIVE;
      scan_only.z = scan_only.height = std::numeric_limits<double>::quiet_NaN();
      scan_only.num_updates = k + 1;
      kept.push_back(scan_only);
    }
    m->tracks = kept;
    m->num_tracks = static_cast<std::int32_t>(kept.size());
  });
  const auto frames_written = [&](const std::vector<std::string>& extra) {
    const std::string out_file = dir_ + "/kitti_s.txt";
    std::vector<std::string> args = {run_, tracks_s, "--kitti-calib", calib, "--kitti-out", out_file,
                                     "--kitti-image-size", "1200x360"};
    args.insert(args.end(), extra.begin(), extra.end());
    std::string out;
    EXPECT_EQ(RunTool(args, &out), 0) << out;
    std::set<long long> frames;
    std::ifstream in(out_file);
    for (std::string l; std::getline(in, l);) {
      std::istringstream ss(l);
      long long frame = 0, id = 0;
      ss >> frame >> id;
      EXPECT_EQ(id, 2) << l;  // never the scan-only tentative track
      frames.insert(frame);
    }
    return frames;
  };
  const auto range = [](int a, int b) {
    std::set<long long> s;
    for (int k = a; k <= b; ++k) s.insert(k);
    return s;
  };
  std::set<long long> expected = {0, 1, 3};  // defaults: tentative box frames, one coasting frame
  for (const long long f : range(4, 10)) expected.insert(f);
  for (const long long f : range(14, kScans - 1)) expected.insert(f);
  EXPECT_EQ(frames_written({}), expected);

  std::set<long long> confirmed = range(4, 9);  // confirmed only
  for (const long long f : range(14, kScans - 1)) confirmed.insert(f);
  EXPECT_EQ(frames_written({"--kitti-tentative", "0", "--kitti-coast-frames", "0"}), confirmed);

  std::set<long long> coast3 = confirmed;  // three coasting frames, no tentative ones
  for (const long long f : range(10, 12)) coast3.insert(f);
  EXPECT_EQ(frames_written({"--kitti-tentative", "0", "--kitti-coast-frames", "3"}), coast3);

  std::set<long long> all_coast = confirmed;  // --score-coasting: every coasting frame
  for (const long long f : range(10, 13)) all_coast.insert(f);
  EXPECT_EQ(frames_written({"--kitti-tentative", "0", "--score-coasting"}), all_coast);

  std::string out;
  EXPECT_EQ(RunTool({run_, tracks_s, "--kitti-calib", calib, "--kitti-out", dir_ + "/x.txt",
                     "--kitti-coast-frames", "-1"}, &out), 2);
  EXPECT_NE(out.find("coast_frames must be >= 0, got -1"), std::string::npos) << out;
}

}  // namespace
}  // namespace vtrack::testing
