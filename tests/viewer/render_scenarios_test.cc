// The real pipeline: vtrack-sim-log writes a scenario's log, vtrack-tracker tracks it offline
// (with TRACK_DEBUG), vtrack-render renders both logs merged. The MP4 must decode with one frame
// per scan (= per TRACKS message), and PNG snapshots must be written. Skips, saying why, when the
// simulator or the tracker is not built or the scenario is missing.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "vtrack/ladar_slice_t.hpp"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"

namespace vtrack::viewer {
namespace {

namespace fs = std::filesystem;
using vtrack::testing::BinDir;
using vtrack::testing::ReadFile;
using vtrack::testing::RunCommand;
using vtrack::testing::ScratchDir;
using vtrack::testing::SourceDir;

// Events per channel; "sweeps": scans whole (LADAR_SCAN) or sent as slices (LADAR_SLICE, one
// sweep per slice 0).
std::map<std::string, int> CountEvents(const std::string& path) {
  std::map<std::string, int> n;
  lcm_util::LogReader r(path);
  while (const auto* ev = r.Next()) {
    ++n[ev->channel];
    if (ev->channel == "LADAR_SCAN") ++n["sweeps"];
    vtrack::ladar_slice_t s;
    if (ev->channel == "LADAR_SLICE" &&
        lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &s) == lcm_util::DecodeError::kNone &&
        s.slice_index == 0) {
      ++n["sweeps"];
    }
  }
  return n;
}

int DecodedFrames(const std::string& mp4, cv::Size* size) {
  cv::VideoCapture cap(mp4, cv::CAP_FFMPEG);
  if (!cap.isOpened()) return -1;
  int n = 0;
  cv::Mat f;
  while (cap.read(f)) {
    *size = f.size();
    ++n;
  }
  return n;
}

struct Scenario {
  const char* name;
  std::vector<std::string> sim_args;  // e.g. a shorter duration for the big scene
  int png_every;
};

class RenderScenarioTest : public ::testing::TestWithParam<Scenario> {};

TEST_P(RenderScenarioTest, VideoHasOneFramePerScan) {
  const Scenario& sc = GetParam();
  for (const char* tool : {"vtrack-sim-log", "vtrack-tracker", "vtrack-render"}) {
    if (!fs::exists(BinDir() + "/" + tool)) {
      GTEST_SKIP() << BinDir() << "/" << tool << " is not built; build it to run this test";
    }
  }
  const std::string scenario = SourceDir() + "/config/scenarios/" + sc.name + ".yaml";
  if (!fs::exists(scenario)) GTEST_SKIP() << scenario << " does not exist";

  const std::string dir = ScratchDir(std::string("render-") + sc.name);
  const std::string run = dir + "/run.lcm", tracks = dir + "/tracks.lcm";
  std::vector<std::string> sim = {BinDir() + "/vtrack-sim-log", "--scenario", sc.name, "--out", run};
  sim.insert(sim.end(), sc.sim_args.begin(), sc.sim_args.end());
  ASSERT_EQ(RunCommand(sim, dir + "/sim.log"), 0) << ReadFile(dir + "/sim.log");
  ASSERT_EQ(RunCommand({BinDir() + "/vtrack-tracker", "--input", run, "--output", tracks, "--debug",
                        "--quiet"},
                       dir + "/tracker.log", std::chrono::milliseconds(600000)),
            0)
      << ReadFile(dir + "/tracker.log");
  const int status = RunCommand(
      {BinDir() + "/vtrack-render", "--input", run, "--input", tracks, "--video", dir + "/out.mp4",
       "--png-dir", dir + "/png", "--png-every", std::to_string(sc.png_every), "--size", "640x480"},
      dir + "/render.log", std::chrono::milliseconds(600000));
  ASSERT_EQ(status, 0) << ReadFile(dir + "/render.log");

  const auto sim_events = CountEvents(run);
  const auto trk_events = CountEvents(tracks);
  const int scans = sim_events.count("sweeps") ? sim_events.at("sweeps") : 0;
  const int lists = trk_events.count("TRACKS") ? trk_events.at("TRACKS") : 0;
  ASSERT_GT(scans, 0);
  EXPECT_GT(trk_events.count("TRACK_DEBUG") ? trk_events.at("TRACK_DEBUG") : 0, 0);
  cv::Size size;
  const int frames = DecodedFrames(dir + "/out.mp4", &size);
  EXPECT_EQ(frames, lists) << "one frame per TRACKS message\n" << ReadFile(dir + "/render.log");
  EXPECT_EQ(frames, scans) << "one frame per scan (the tracker answered every scan?)\n"
                           << ReadFile(dir + "/tracker.log");
  EXPECT_EQ(size, cv::Size(640, 480));

  std::size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(dir + "/png")) {
    if (e.path().extension() != ".png") continue;
    ++pngs;
    EXPECT_EQ(cv::imread(e.path().string()).size(), cv::Size(640, 480)) << e.path();
  }
  EXPECT_EQ(pngs, static_cast<std::size_t>((frames + sc.png_every - 1) / sc.png_every));
}

// paper_fig4_turn in full (16 s, 25 Hz single-plane scans); urban_intersection (64-layer cloud)
// for its first 4 s, to keep the test in seconds: README gives the command for the whole run.
INSTANTIATE_TEST_SUITE_P(Scenarios, RenderScenarioTest,
                         ::testing::Values(Scenario{"paper_fig4_turn", {}, 100},
                                           Scenario{"urban_intersection", {"--duration", "4"}, 10}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace vtrack::viewer
