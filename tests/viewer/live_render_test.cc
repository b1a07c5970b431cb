// Live rendering on an in-process bus (memq://): every frame is drawn when the renderer keeps up;
// when it does not, the LCM thread still handles every message at once (it never waits for the
// drawing), the newest frame is drawn next, and the frames skipped are counted.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "tests/viewer/test_messages.h"
#include "viewer/live_render.h"

namespace vtrack::viewer {
namespace {

using testing::EgoArc;
using testing::TrackAt;
using testing::TrackList;

constexpr std::int64_t kPeriod = 100'000;  // [us]

template <class T>
void Publish(lcm::LCM& lcm, const std::string& channel, const T& msg) {
  ASSERT_EQ(lcm.publish(channel, &msg), 0);
}

// Publishes the poses, scan and track list of scan k (poses run 0.1 s past the scan).
void PublishScan(lcm::LCM& lcm, const EgoArc& ego, int k) {
  const std::int64_t t = ego.t0 + k * kPeriod;
  for (std::int64_t p = t; p < t + kPeriod; p += 20'000) Publish(lcm, "EGO_POSE", ego.Pose(p));
  Publish(lcm, "LADAR_SCAN", testing::ScanOf(ego, t, k, {{10.0, 5.0, 0.0}}, {0}));
  Publish(lcm, "TRACKS", TrackList(t, k, {TrackAt(1, 10.0 + k, 0.0, 0.0)}));
}

std::int64_t Handled(const LiveRenderer& r) {
  return r.stats().messages + r.stats().decode_errors;
}

// Handles messages until none is left (memq:// queues what this thread published).
void Drain(LiveRenderer& r) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    const std::int64_t before = Handled(r);
    ASSERT_TRUE(r.HandleOnce(0));
    if (Handled(r) == before) return;
  }
  FAIL() << "messages were not handled in 20 s";
}

// The bus never goes quiet long enough in these tests for the idle flush to matter.
constexpr std::chrono::milliseconds kNoIdleFlush(60'000);

RenderJob SmallJob() {
  RenderJob job;
  job.render.width = 320;
  job.render.height = 240;
  job.assembler.trigger = AssemblerParams::Trigger::kTracks;
  return job;
}

TEST(LiveRendererTest, EveryFrameWhenTheRendererKeepsUp) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  std::mutex m;
  std::vector<std::int64_t> drawn;
  LiveRenderer r(
      &lcm, SmallJob(),
      [&](const Scene& s, const cv::Mat& img) {
        EXPECT_EQ(img.cols, 320);
        std::lock_guard<std::mutex> lock(m);
        drawn.push_back(s.utime);
      },
      kNoIdleFlush);
  const EgoArc ego;
  constexpr int kScans = 12;
  for (int k = 0; k < kScans + 4; ++k) {  // 4 more scans of poses carry the data clock on
    if (k < kScans) {
      PublishScan(lcm, ego, k);
    } else {
      for (std::int64_t p = 0; p < kPeriod; p += 20'000) {
        Publish(lcm, "EGO_POSE", ego.Pose(ego.t0 + k * kPeriod + p));
      }
    }
    Drain(r);
    // Wait for the drawing before the next scan: a renderer that keeps up.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (r.stats().frames_rendered < r.stats().frames_ready &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  r.Finish();
  const LiveStats s = r.stats();
  EXPECT_EQ(s.frames_ready, kScans);
  EXPECT_EQ(s.frames_rendered, kScans);
  EXPECT_EQ(s.frames_dropped, 0);
  ASSERT_EQ(drawn.size(), static_cast<std::size_t>(kScans));
  for (int k = 0; k < kScans; ++k) EXPECT_EQ(drawn[static_cast<std::size_t>(k)], ego.t0 + k * kPeriod);
}

TEST(LiveRendererTest, SlowRendererDropsFramesAndNeverBlocksTheBus) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  std::mutex m;
  std::condition_variable cv;
  bool release = false;
  std::atomic<int> calls{0};
  std::vector<std::int64_t> drawn;
  // The sink blocks on its first frame until the test releases it.
  LiveRenderer r(
      &lcm, SmallJob(),
      [&](const Scene& s, const cv::Mat&) {
        std::unique_lock<std::mutex> lock(m);
        drawn.push_back(s.utime);
        if (calls++ == 0) cv.wait(lock, [&] { return release; });
      },
      kNoIdleFlush);
  const EgoArc ego;
  constexpr int kScans = 15;
  // Scans 0-3 make frame 0 ready (the data clock passes its time + lag), not yet frame 1; the
  // renderer takes frame 0 and is stuck in the sink.
  for (int k = 0; k < 4; ++k) PublishScan(lcm, ego, k);
  Drain(r);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (calls.load() == 0 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(calls.load(), 1);
  for (int k = 4; k < kScans; ++k) PublishScan(lcm, ego, k);
  for (int k = kScans; k < kScans + 5; ++k) {
    for (std::int64_t p = 0; p < kPeriod; p += 20'000) {
      Publish(lcm, "EGO_POSE", ego.Pose(ego.t0 + k * kPeriod + p));
    }
  }
  // Every message is handled and every frame put together while the renderer is stuck on the
  // first one: the LCM thread does not wait for drawing.
  Drain(r);
  EXPECT_EQ(r.stats().frames_ready, kScans);
  EXPECT_EQ(calls.load(), 1);
  {
    std::lock_guard<std::mutex> lock(m);
    release = true;
  }
  cv.notify_all();
  r.Finish();
  const LiveStats s = r.stats();
  // Drawn: the first frame and then the newest; the 13 in between were replaced and counted.
  EXPECT_EQ(s.frames_rendered, 2);
  EXPECT_EQ(s.frames_dropped, kScans - 2);
  ASSERT_EQ(drawn.size(), 2u);
  EXPECT_EQ(drawn[0], ego.t0);
  EXPECT_EQ(drawn[1], ego.t0 + (kScans - 1) * kPeriod);
}

// Every TRACKS message is accounted for: drawn, replaced before it could be drawn, or too late to
// be drawn in order (a tracker that fell behind, or was restarted).
TEST(LiveRendererTest, TracksTooLateToDrawAreCounted) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  LiveRenderer r(&lcm, SmallJob(), [](const Scene&, const cv::Mat&) {}, kNoIdleFlush);
  const EgoArc ego;
  constexpr int kScans = 10;
  for (int k = 0; k < kScans; ++k) {
    const std::int64_t t = ego.t0 + k * kPeriod;
    for (std::int64_t p = t; p < t + kPeriod; p += 20'000) Publish(lcm, "EGO_POSE", ego.Pose(p));
    Publish(lcm, "LADAR_SCAN", testing::ScanOf(ego, t, k, {{10.0, 5.0, 0.0}}, {0}));
    if (k != 3) Publish(lcm, "TRACKS", TrackList(t, k, {TrackAt(1, 10.0 + k, 0.0, 0.0)}));
  }
  // The answer to scan 3 after the frames of scans 4-6 have gone out.
  Publish(lcm, "TRACKS", TrackList(ego.t0 + 3 * kPeriod, 3, {TrackAt(1, 13.0, 0.0, 0.0)}));
  Drain(r);
  r.Finish();
  const LiveStats s = r.stats();
  EXPECT_EQ(s.tracks_received, kScans);
  EXPECT_EQ(s.tracks_late, 1);
  EXPECT_EQ(s.frames_rendered + s.frames_dropped, kScans - 1);
  EXPECT_EQ(s.frames_rendered + s.frames_dropped + s.tracks_late, s.tracks_received);
}

TEST(LiveRendererTest, AFailingSinkStopsRenderingWithItsError) {
  lcm::LCM lcm("memq://");
  LiveRenderer r(
      &lcm, SmallJob(),
      [](const Scene&, const cv::Mat&) { throw std::runtime_error("disk full on /videos"); },
      kNoIdleFlush);
  const EgoArc ego;
  for (int k = 0; k < 6; ++k) PublishScan(lcm, ego, k);
  Drain(r);
  r.Finish();
  EXPECT_TRUE(r.failed());
  EXPECT_EQ(r.error(), "disk full on /videos");
}

TEST(LiveRendererTest, UndecodableMessagesAreCounted) {
  lcm::LCM lcm("memq://");
  LiveRenderer r(&lcm, SmallJob(), [](const Scene&, const cv::Mat&) {});
  const std::string junk = "not a scan";
  lcm.publish("LADAR_SCAN", junk.data(), static_cast<unsigned>(junk.size()));
  lcm.publish("TRACKS", junk.data(), static_cast<unsigned>(junk.size()));
  Drain(r);
  EXPECT_EQ(r.stats().decode_errors, 2);
  EXPECT_EQ(r.stats().messages, 0);
}

}  // namespace
}  // namespace vtrack::viewer
