// Replay (deploy/README.md), the renderer's side: lcm-logplayer plays a recorded log into a live tracker
// and a live renderer (udpm:// inside the private network namespace ctest gives this test), and
// the frames drawn live are the frames of the offline run (vtrack-tracker --input, then
// vtrack-render --input over both logs): every TRACKS message of the run gives a frame or a
// counted drop, and every frame drawn live is, pixel for pixel, one of the offline frames, in
// order. Only the corner text is left out of the comparison: it shows the tracker's measured
// latency, which differs from run to run.
// The tracker's side (lcm-logplayer vs offline: identical tracks) is tracker_live_test's
// LogPlayedLiveGivesTheSameTracksAsOffline; it is not repeated here.
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"

namespace vtrack::testing {
namespace {

using namespace std::chrono_literals;
namespace fs = std::filesystem;

constexpr char kUrl[] = "udpm://239.255.76.67:7667?ttl=0";
constexpr int kScans = 150;  // paper_fig4_turn: 6 s at 25 Hz
constexpr int kTextBandPx = 80;  // the top rows: time, scan, mode, tracks, latency

std::string Bin(const std::string& name) { return BinDir() + "/" + name; }

std::vector<std::string> Pngs(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".png") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

cv::Mat Body(const std::string& png) {
  const cv::Mat img = cv::imread(png, cv::IMREAD_COLOR);
  if (img.empty()) return img;
  return img.rowRange(kTextBandPx, img.rows).clone();
}

int DifferingPixels(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return -1;
  cv::Mat diff, any;
  cv::absdiff(a, b, diff);
  cv::cvtColor(diff, any, cv::COLOR_BGR2GRAY);
  return cv::countNonZero(any);
}

TEST(ReplayRenderTest, LogPlayedIntoLiveTrackerAndRendererDrawsTheOfflineFrames) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = ScratchDir("replay_render");
  const std::string sim = dir + "/run.lcm", tracks = dir + "/tracks.lcm";
  const std::vector<std::string> view{"--size", "640x480", "--hide-truth", "--no-legend", "--png-every", "1"};
  ASSERT_EQ(RunCommand({Bin("vtrack-sim-log"), "--scenario", "paper_fig4_turn", "--duration", "6",
                        "--out", sim, "-q"}, dir + "/sim.txt"), 0) << ReadFile(dir + "/sim.txt");

  // Offline: the tracker over the log, then the renderer over both logs.
  ASSERT_EQ(RunCommand({Bin("vtrack-tracker"), "--input", sim, "--output", tracks, "--debug", "-q"},
                       dir + "/tracker_offline.txt"), 0) << ReadFile(dir + "/tracker_offline.txt");
  std::vector<std::string> offline{Bin("vtrack-render"), "--input", sim, "--input", tracks,
                                   "--png-dir", dir + "/offline_png", "-q"};
  offline.insert(offline.end(), view.begin(), view.end());
  ASSERT_EQ(RunCommand(offline, dir + "/render_offline.txt"), 0) << ReadFile(dir + "/render_offline.txt");
  const std::vector<std::string> offline_pngs = Pngs(dir + "/offline_png");
  ASSERT_EQ(offline_pngs.size(), static_cast<std::size_t>(kScans));

  // Live: lcm-logplayer publishes the log in real time to the tracker and the renderer.
  std::string render_out;
  {
    std::vector<std::string> live{Bin("vtrack-render"), "--lcm-url", kUrl, "--png-dir", dir + "/live_png"};
    live.insert(live.end(), view.begin(), view.end());
    Subprocess render(live, dir + "/render_live.txt");
    // Ids from 1, as offline: the frames show them.
    Subprocess tracker({Bin("vtrack-tracker"), "--lcm-url", kUrl, "--debug", "--first-track-id", "1"},
                       dir + "/tracker_live.txt");
    std::this_thread::sleep_for(1500ms);  // both subscribed
    const int rc = RunCommand({"lcm-logplayer", "-l", kUrl, sim}, dir + "/player.txt", 60s);
    EXPECT_EQ(rc, 0) << ReadFile(dir + "/player.txt");
    std::this_thread::sleep_for(1500ms);  // past the renderer's lag: the last frame is drawn
    EXPECT_EQ(tracker.Stop(), 0) << ReadFile(dir + "/tracker_live.txt");
    render.Signal(SIGINT);
    const auto status = render.Wait(30s);
    EXPECT_TRUE(status && *status == 0) << ReadFile(dir + "/render_live.txt");
    render_out = ReadFile(dir + "/render_live.txt");
  }
  int rendered = -1, dropped = -1;
  const std::regex total(R"((\d+) frames rendered, (\d+) dropped)");
  for (auto it = std::sregex_iterator(render_out.begin(), render_out.end(), total);
       it != std::sregex_iterator(); ++it) {
    rendered = std::stoi((*it)[1]);
    dropped = std::stoi((*it)[2]);
  }
  ASSERT_GE(rendered, 0) << render_out;
  EXPECT_EQ(rendered + dropped, kScans) << "every TRACKS message is a frame or a counted drop\n" << render_out;
  const std::vector<std::string> live_pngs = Pngs(dir + "/live_png");
  EXPECT_EQ(live_pngs.size(), static_cast<std::size_t>(rendered));
  EXPECT_GE(rendered, kScans / 2) << render_out;

  // Each live frame is an offline frame, in order: the next one, or one of the following
  // `dropped` ones (a dropped frame is skipped).
  std::size_t j = 0;
  int matched = 0, worst = 0, skips_left = std::max(dropped, 0);
  for (const std::string& png : live_pngs) {
    const cv::Mat a = Body(png);
    ASSERT_FALSE(a.empty()) << png;
    int best = -1;
    std::size_t k = j;
    const std::size_t end = std::min(offline_pngs.size(), j + static_cast<std::size_t>(skips_left) + 1);
    for (; k < end; ++k) {
      const int d = DifferingPixels(a, Body(offline_pngs[k]));
      if (best < 0 || (d >= 0 && d < best)) best = d;
      if (d == 0) break;
    }
    if (k == end) {
      ADD_FAILURE() << png << " is none of the offline frames " << j << ".." << end - 1
                    << " (fewest differing pixels: " << best << ")";
      worst = std::max(worst, best);
      ++j;
      continue;
    }
    ++matched;
    skips_left -= static_cast<int>(k - j);
    j = k + 1;
  }
  std::printf("live replay: %d frames rendered, %d dropped; %d of them equal an offline frame, in "
              "order (largest difference of the others: %d pixels)\n", rendered, dropped, matched, worst);
  EXPECT_EQ(matched, rendered);
}

}  // namespace
}  // namespace vtrack::testing
