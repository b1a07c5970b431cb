// vtrack-render offline, end to end: a log with known content (N scans, N track lists, debug,
// truth, ego poses) is rendered by the executable; the MP4 must decode to exactly N frames, PNG
// snapshots must appear where asked, and what they show must be where the known geometry puts
// it. Also the executable's handling of bad options and bad input.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "lcmtypes/util/ladar_slices.h"
#include "lcmtypes/util/log_reader.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "tests/viewer/pixel_util.h"
#include "tests/viewer/test_messages.h"
#include "viewer/renderer.h"

namespace vtrack::viewer {
namespace {

namespace fs = std::filesystem;
using testing::ColorNear;
using testing::EgoArc;
using vtrack::testing::BinDir;
using vtrack::testing::ReadFile;
using vtrack::testing::RunCommand;
using vtrack::testing::ScratchDir;

constexpr std::int64_t kPeriod = 100'000;  // [us] 10 Hz

// The fixed window every test renders: 40 m x 30 m at 20 px/m in 800 x 600.
const std::vector<std::string> kWindow = {"--window", "0,-10,40,20", "--size", "800x600"};
Eigen::Vector2d Project(const Eigen::Vector2d& w) {
  return {400.0 + 20.0 * (w.x() - 20.0), 300.0 - 20.0 * (w.y() - 5.0)};
}

// Known scene: a wall of points along y = 9.5 m (below the legend) and a tracked car at
// (6 + 0.5 k, 4) on scan k.
std::vector<Eigen::Vector3d> WallPoints() {
  std::vector<Eigen::Vector3d> w;
  for (double x = 2.0; x <= 36.0; x += 2.0) w.emplace_back(x, 9.5, 0.5);
  return w;
}
Eigen::Vector2d CarAt(int k) { return {6.0 + 0.5 * k, 4.0}; }

struct LogSpec {
  int scans = 30;
  bool tracks = true;
  bool split = false;          // scans/poses/truth in one log, tracks/debug in another
  bool garbage_tracks = false; // one undecodable TRACKS message
  int slices = 0;              // > 0: each scan written as that many LADAR_SLICE messages
};

// Writes the log(s) and returns their paths.
std::vector<std::string> WriteLogs(const std::string& dir, const LogSpec& spec) {
  const EgoArc ego;
  const std::string sim_path = dir + "/run.lcm", trk_path = dir + "/tracks.lcm";
  std::vector<std::string> paths = {sim_path};
  if (spec.split) paths.push_back(trk_path);
  lcm_util::LogWriter sim(sim_path);
  std::unique_ptr<lcm_util::LogWriter> trk;
  if (spec.split) trk = std::make_unique<lcm_util::LogWriter>(trk_path);
  lcm_util::LogWriter& out = spec.split ? *trk : sim;
  const auto wall = WallPoints();
  std::vector<std::int32_t> dt;
  for (std::size_t i = 0; i < wall.size(); ++i) dt.push_back(static_cast<std::int32_t>(4000 * i));
  for (int k = 0; k < spec.scans; ++k) {
    const std::int64_t t = ego.t0 + k * kPeriod;
    for (std::int64_t p = t; p < t + kPeriod; p += 20'000) sim.WriteMessage(p, "EGO_POSE", ego.Pose(p));
    // The scan is published when the sweep ends; the tracker answers a few ms later.
    const ladar_scan_t scan = testing::ScanOf(ego, t, k, wall, dt);
    if (spec.slices > 0) {
      for (const ladar_slice_t& s : lcm_util::SliceSweep(scan, spec.slices)) {
        sim.WriteMessage(t + kPeriod, "LADAR_SLICE", s);
      }
    } else {
      sim.WriteMessage(t + kPeriod, "LADAR_SCAN", scan);
    }
    sim.WriteMessage(t + kPeriod, "GROUND_TRUTH",
                     testing::TruthAt(t, k, 77, CarAt(k).x() + 0.2, CarAt(k).y(), 0.0));
    if (!spec.tracks) continue;
    const auto list = testing::TrackList(t, k, {testing::TrackAt(3, CarAt(k).x(), CarAt(k).y(), 0.0)});
    out.WriteMessage(t + kPeriod + 4000, "TRACKS", list);
    out.WriteMessage(t + kPeriod + 4500, "TRACK_DEBUG", testing::DebugFor(list));
    if (spec.garbage_tracks && k == 5) {
      const std::string junk = "this is not a track list";
      out.Write(t + kPeriod + 4600, "TRACKS", junk.data(), junk.size());
    }
  }
  return paths;
}

int DecodedFrames(const std::string& mp4) {
  cv::VideoCapture cap(mp4, cv::CAP_FFMPEG);
  if (!cap.isOpened()) return -1;
  int n = 0;
  cv::Mat f;
  while (cap.read(f)) ++n;
  return n;
}

std::size_t CountPngs(const std::string& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path().extension() == ".png";
  return n;
}

struct Run {
  int status;
  std::string output;
};

Run Render(const std::string& dir, std::vector<std::string> args) {
  args.insert(args.begin(), BinDir() + "/vtrack-render");
  const std::string log = dir + "/render.log";
  const int status = RunCommand(args, log, std::chrono::milliseconds(120000));
  return {status, ReadFile(log)};
}

std::vector<std::string> Inputs(const std::vector<std::string>& paths) {
  std::vector<std::string> a;
  for (const auto& p : paths) {
    a.push_back("--input");
    a.push_back(p);
  }
  return a;
}

std::vector<std::string> Cat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

class RenderLogTest : public ::testing::TestWithParam<bool> {};

TEST_P(RenderLogTest, OneVideoFramePerScanAndPngsWhereAsked) {
  const bool split = GetParam();
  const std::string dir = ScratchDir(split ? "render-log-split" : "render-log");
  const auto logs = WriteLogs(dir, {.scans = 30, .split = split});
  const auto r = Render(dir, Cat(Cat(Inputs(logs), kWindow),
                                 {"--video", dir + "/out.mp4", "--png-dir", dir + "/png",
                                  "--png-every", "10", "--png-at", "1.55"}));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(DecodedFrames(dir + "/out.mp4"), 30) << r.output;
  EXPECT_NE(r.output.find("30 frames (one per TRACKS message"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("10.00 fps"), std::string::npos) << r.output;
  // Frames 0, 10, 20 and the first at or after 1.55 s (frame 16 at 1.6 s).
  EXPECT_EQ(CountPngs(dir + "/png"), 4u);
  for (int k : {0, 10, 16, 20}) {
    char name[32];
    std::snprintf(name, sizeof(name), "/png/frame_%06d.png", k);
    const cv::Mat img = cv::imread(dir + name);
    ASSERT_FALSE(img.empty()) << name;
    ASSERT_EQ(img.cols, 800);
    // The track's rectangle (4.5 m x 1.9 m, heading 0) at its position on scan k.
    const Eigen::Vector2d c = CarAt(k);
    for (const Eigen::Vector2d& corner : {Eigen::Vector2d(2.25, 0.95), Eigen::Vector2d(-2.25, 0.95),
                                         Eigen::Vector2d(-2.25, -0.95), Eigen::Vector2d(2.25, -0.95)}) {
      EXPECT_TRUE(ColorNear(img, color::kState, Project(c + corner), 1.5)) << name;
    }
    // The wall's points, placed with the ego pose of each return's own time (except where the
    // ego vehicle, drawn over the points, drives past them).
    const Eigen::Vector2d ego = EgoArc{}.WorldFromBody(EgoArc{}.t0 + k * kPeriod).translation().head<2>();
    for (const auto& w : WallPoints()) {
      if ((w.head<2>() - ego).norm() < 3.5) continue;
      EXPECT_TRUE(ColorNear(img, color::kPoint, Project(w.head<2>()), 1.5))
          << name << " wall point " << w.transpose();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(OneOrTwoLogs, RenderLogTest, ::testing::Values(false, true));

TEST(RenderLogTest, ScansOnlyLogGivesOneFramePerScan) {
  const std::string dir = ScratchDir("render-log-scans");
  const auto logs = WriteLogs(dir, {.scans = 12, .tracks = false});
  const auto r = Render(dir, Cat(Inputs(logs), {"--video", dir + "/scans.mp4", "--quiet"}));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(DecodedFrames(dir + "/scans.mp4"), 12);
  EXPECT_NE(r.output.find("one per LADAR_SCAN"), std::string::npos) << r.output;
}

// The same scans sent as slices: the renderer joins them and draws the same frames, pixel for
// pixel, as from the whole scans.
TEST(RenderLogTest, SlicedScansDrawTheFramesOfWholeScans) {
  const std::string dir = ScratchDir("render-log-sliced");
  fs::create_directories(dir + "/whole");
  fs::create_directories(dir + "/sliced");
  const auto whole = WriteLogs(dir + "/whole", {.scans = 12, .tracks = false});
  const auto sliced = WriteLogs(dir + "/sliced", {.scans = 12, .tracks = false, .slices = 4});
  for (const auto& [logs, sub] : {std::pair{whole, "/whole"}, std::pair{sliced, "/sliced"}}) {
    const auto r = Render(dir, Cat(Cat(Inputs(logs), kWindow),
                                   {"--video", dir + sub + "/v.mp4", "--png-dir", dir + sub + "/png",
                                    "--png-every", "1", "--quiet"}));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(DecodedFrames(dir + sub + "/v.mp4"), 12) << sub;
  }
  ASSERT_EQ(CountPngs(dir + "/sliced/png"), 12u);
  for (int k = 0; k < 12; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "/png/frame_%06d.png", k);
    const cv::Mat a = cv::imread(dir + "/whole" + name), b = cv::imread(dir + "/sliced" + name);
    ASSERT_FALSE(a.empty()) << name;
    ASSERT_FALSE(b.empty()) << name;
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << name;
  }
}

TEST(RenderLogTest, UndecodableMessageIsCountedAndSkipped) {
  const std::string dir = ScratchDir("render-log-garbage");
  const auto logs = WriteLogs(dir, {.scans = 10, .garbage_tracks = true});
  const auto r = Render(dir, Cat(Inputs(logs), {"--video", dir + "/g.mp4"}));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(DecodedFrames(dir + "/g.mp4"), 10);
  EXPECT_NE(r.output.find("cannot decode a message on TRACKS"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 decode errors"), std::string::npos) << r.output;
}

TEST(RenderLogTest, StartEndAndMaxFrames) {
  const std::string dir = ScratchDir("render-log-range");
  const auto logs = WriteLogs(dir, {.scans = 30});
  auto r = Render(dir, Cat(Inputs(logs), {"--video", dir + "/r.mp4", "--start", "1.0", "--end", "1.95"}));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(DecodedFrames(dir + "/r.mp4"), 10);  // 1.0, 1.1, ..., 1.9 s
  r = Render(dir, Cat(Inputs(logs), {"--video", dir + "/m.mp4", "--max-frames", "7"}));
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(DecodedFrames(dir + "/m.mp4"), 7);
  // A window past the logs' end draws nothing: said, and not a success.
  r = Render(dir, Cat(Inputs(logs), {"--video", dir + "/late.mp4", "--start", "1000"}));
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("nothing written (no video " + dir + "/late.mp4)"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/late.mp4"));
  r = Render(dir, Cat(Inputs(logs), {"--png-dir", dir + "/png", "--png-at", "1000"}));
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("or none at a --png-at time"), std::string::npos) << r.output;
  // Live, a display stopped before anything came says so, and that is no failure.
  r = Render(dir, {"--lcm-url", "memq://", "--duration", "0.3", "--video", dir + "/live.mp4"});
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("nothing written (no video " + dir + "/live.mp4): no frame came on the bus"),
            std::string::npos) << r.output;
}

TEST(RenderMainTest, HelpAndBadOptions) {
  const std::string dir = ScratchDir("render-options");
  auto r = Render(dir, {"--help"});
  EXPECT_EQ(r.status, 0);
  for (const char* opt : {"--input", "--video", "--png-dir", "--png-every", "--png-at", "--zoom",
                          "--window", "--hypotheses", "--hide-clutter", "--fps", "--lcm-url"}) {
    EXPECT_NE(r.output.find(opt), std::string::npos) << opt;
  }
  const std::vector<std::pair<std::vector<std::string>, std::string>> bad = {
      {{"--input", "x.lcm"}, "nothing to write"},
      {{"--video", "v.mp4", "--size", "1281x960"}, "1281"},
      {{"--video", "v.mp4", "--size", "big"}, "--size 'big'"},
      {{"--video", "v.mp4", "--window", "1,2,3"}, "--window '1,2,3'"},
      {{"--video", "v.mp4", "--window", "5,0,1,10"}, "XMIN < XMAX"},
      {{"--video", "v.mp4", "--window", "0,0,10,10", "--zoom", "4"}, "--window and --zoom"},
      {{"--video", "v.mp4", "--frame-on", "sometimes"}, "'sometimes'"},
      {{"--video", "v.mp4", "--ground", "flat"}, "'flat'"},
      {{"--video", "v.mp4", "--ellipse-sigma", "-1"}, "ellipse_sigma = -1"},
      {{"--video", "v.mp4", "--png-every", "3"}, "png_dir"},
      {{"--video", "v.mp4", "--zoom", "abc"}, "zoom"},
      {{"--video", "v.mp4", "--no-such-option"}, "no-such-option"},
  };
  for (const auto& [args, expect] : bad) {
    r = Render(dir, args);
    EXPECT_EQ(r.status, 2) << args.back() << "\n" << r.output;
    EXPECT_NE(r.output.find(expect), std::string::npos) << expect << "\n" << r.output;
  }
}

TEST(RenderMainTest, BadInputAndOutputFailWithTheirNames) {
  const std::string dir = ScratchDir("render-bad-io");
  auto r = Render(dir, {"--input", dir + "/missing.lcm", "--video", dir + "/v.mp4"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("missing.lcm"), std::string::npos) << r.output;

  const auto logs = WriteLogs(dir, {.scans = 3});
  r = Render(dir, Cat(Inputs(logs), {"--video", "/nonexistent-vtrack-dir/v.mp4"}));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("/nonexistent-vtrack-dir"), std::string::npos) << r.output;

  {
    lcm_util::LogWriter w(dir + "/other.lcm");
    w.Write(1, "SOMETHING_ELSE", "x", 1);
  }
  r = Render(dir, {"--input", dir + "/other.lcm", "--video", dir + "/o.mp4"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("nothing to render"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("SOMETHING_ELSE (1)"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace vtrack::viewer
