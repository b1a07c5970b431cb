// vtrack-render live on a real LCM bus (udpm:// inside a private network namespace: ctest runs
// this through scripts/vtrack-netns): frames published by this test at 20 Hz are rendered or
// counted as dropped, the video holds exactly the rendered ones, and SIGINT ends it cleanly.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>
#include <opencv2/videoio.hpp>

#include <csignal>
#include <cstdio>
#include <regex>
#include <thread>

#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "tests/viewer/test_messages.h"

namespace vtrack::viewer {
namespace {

using namespace std::chrono_literals;
using vtrack::testing::BinDir;
using vtrack::testing::ReadFile;
using vtrack::testing::ScratchDir;
using vtrack::testing::Subprocess;

constexpr char kUrl[] = "udpm://239.255.76.67:7667?ttl=0";
constexpr std::int64_t kPeriod = 100'000;  // [us] data time between scans

bool WaitForText(const std::string& path, const std::string& text, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (ReadFile(path).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(50ms);
  }
  return false;
}

TEST(LiveBusTest, RendersOrCountsEveryFrameAndStopsOnSigint) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = ScratchDir("render-live-bus");
  const std::string log = dir + "/render.log";
  Subprocess render({BinDir() + "/vtrack-render", "--lcm-url", kUrl, "--video", dir + "/live.mp4",
                     "--png-dir", dir + "/png", "--png-every", "5", "--size", "320x240",
                     "--frame-on", "tracks"},
                    log);
  ASSERT_TRUE(WaitForText(log, "rendering live from", 20s)) << ReadFile(log);
  EXPECT_NE(ReadFile(log).find("recv_buf_size=4194304"), std::string::npos) << ReadFile(log);

  lcm::LCM lcm(kUrl);
  ASSERT_TRUE(lcm.good());
  const testing::EgoArc ego;
  constexpr int kScans = 20;
  for (int k = 0; k < kScans + 5; ++k) {
    const std::int64_t t = ego.t0 + k * kPeriod;
    for (std::int64_t p = t; p < t + kPeriod; p += 20'000) {
      const auto pose = ego.Pose(p);
      lcm.publish("EGO_POSE", &pose);
    }
    if (k < kScans) {
      const auto scan = testing::ScanOf(ego, t, k, {{10.0, 5.0, 0.0}, {12.0, -3.0, 0.5}}, {0, 500});
      lcm.publish("LADAR_SCAN", &scan);
      const auto tracks = testing::TrackList(t, k, {testing::TrackAt(2, 10.0 + 0.5 * k, 1.0, 0.0)});
      lcm.publish("TRACKS", &tracks);
    }
    std::this_thread::sleep_for(50ms);  // 20 Hz
  }
  std::this_thread::sleep_for(1500ms);  // past the idle flush: every frame has been offered
  render.Signal(SIGINT);
  const auto status = render.Wait(20s);
  ASSERT_TRUE(status.has_value()) << "vtrack-render did not stop on SIGINT\n" << ReadFile(log);
  EXPECT_EQ(*status, 0) << ReadFile(log);

  const std::string out = ReadFile(log);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"((\d+) frames rendered, (\d+) dropped)")))
      << out;
  const int rendered = std::stoi(m[1]), dropped = std::stoi(m[2]);
  EXPECT_EQ(rendered + dropped, kScans) << out;
  EXPECT_GE(rendered, 1);
  cv::VideoCapture cap(dir + "/live.mp4", cv::CAP_FFMPEG);
  ASSERT_TRUE(cap.isOpened());
  int frames = 0;
  cv::Mat f;
  while (cap.read(f)) ++frames;
  EXPECT_EQ(frames, rendered) << out;
}

}  // namespace
}  // namespace vtrack::viewer
