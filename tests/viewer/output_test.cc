// Video and PNG output, merged log reading, the newest-frame mailbox and the LCM URL helper.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "lcmtypes/util/log_reader.h"
#include "tests/support/test_env.h"
#include "viewer/frame_output.h"
#include "viewer/latest_slot.h"
#include "viewer/live_render.h"
#include "viewer/log_merge.h"

namespace vtrack::viewer {
namespace {

namespace fs = std::filesystem;

// Frame i carries its number as the brightness of a block, so decoded frames can be told apart.
cv::Mat NumberedFrame(int i) {
  cv::Mat m(240, 320, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::rectangle(m, cv::Rect(40, 40, 120, 120), cv::Scalar::all(10 * i), cv::FILLED);
  return m;
}

int CountFrames(const std::string& path, std::vector<double>* brightness = nullptr,
                double* fps = nullptr) {
  cv::VideoCapture cap(path, cv::CAP_FFMPEG);
  if (!cap.isOpened()) return -1;
  if (fps) *fps = cap.get(cv::CAP_PROP_FPS);
  int n = 0;
  cv::Mat f;
  while (cap.read(f)) {
    if (brightness) brightness->push_back(cv::mean(f(cv::Rect(60, 60, 80, 80)))[0]);
    ++n;
  }
  return n;
}

TEST(FrameOutputTest, VideoAtTheScanRateWithEveryFrameInOrder) {
  const std::string dir = vtrack::testing::ScratchDir("viewer-output");
  OutputParams p;
  p.video_path = dir + "/out.mp4";
  p.png_dir = dir + "/png";
  p.png_every = 3;
  p.png_at_s = {0.12, 0.3};
  {
    FrameOutput out(p);
    for (int i = 0; i < 12; ++i) {
      out.Write(NumberedFrame(i), 1'000'000 + i * 50'000, 0.05 * i);  // 20 Hz data
    }
    out.Close();
    EXPECT_DOUBLE_EQ(out.fps(), 20.0);
    EXPECT_EQ(out.video_frames(), 12);
    // Every 3rd frame (0, 3, 6, 9) and the first at or after 0.12 s (3) and 0.3 s (6).
    ASSERT_EQ(out.png_paths().size(), 4u);
    EXPECT_EQ(fs::path(out.png_paths()[1]).filename(), "frame_000003.png");
  }
  std::vector<double> b;
  double fps = 0.0;
  EXPECT_EQ(CountFrames(p.video_path, &b, &fps), 12);
  EXPECT_NEAR(fps, 20.0, 1e-6);
  for (int i = 0; i < 12; ++i) EXPECT_NEAR(b[static_cast<std::size_t>(i)], 10.0 * i, 6.0) << i;
  const cv::Mat png = cv::imread(p.png_dir + "/frame_000009.png");
  ASSERT_FALSE(png.empty());
  EXPECT_NEAR(cv::mean(png(cv::Rect(60, 60, 80, 80)))[0], 90.0, 0.5);  // lossless
}

TEST(FrameOutputTest, FewFramesAndAGivenRate) {
  const std::string dir = vtrack::testing::ScratchDir("viewer-output-few");
  OutputParams p;
  p.video_path = dir + "/few.mp4";
  {
    FrameOutput out(p);
    for (int i = 0; i < 3; ++i) out.Write(NumberedFrame(i), i * 40'000, 0.04 * i);
  }  // the destructor closes: frames held for the rate estimate are written
  double fps = 0.0;
  EXPECT_EQ(CountFrames(p.video_path, nullptr, &fps), 3);
  EXPECT_NEAR(fps, 25.0, 1e-6);
  p.video_path = dir + "/given.mp4";
  p.fps = 7.0;
  {
    FrameOutput out(p);
    out.Write(NumberedFrame(0), 0, 0.0);
  }
  EXPECT_EQ(CountFrames(p.video_path, nullptr, &fps), 1);
  EXPECT_NEAR(fps, 7.0, 1e-6);
}

TEST(FrameOutputTest, ClearErrors) {
  OutputParams p;
  p.video_path = "/nonexistent-dir-vtrack/out.mp4";
  try {
    FrameOutput out(p);
    FAIL() << "no error for a missing directory";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir-vtrack"), std::string::npos) << e.what();
  }
  OutputParams q;
  q.png_every = 5;
  std::string error;
  EXPECT_FALSE(q.Validate(&error));
  EXPECT_NE(error.find("png_dir"), std::string::npos) << error;
  q.png_dir = "/tmp";
  q.fps = -1.0;
  EXPECT_FALSE(q.Validate(&error));
  EXPECT_NE(error.find("fps = -1"), std::string::npos) << error;

  const std::string dir = vtrack::testing::ScratchDir("viewer-output-size");
  OutputParams r;
  r.png_dir = dir;
  r.png_every = 1;
  FrameOutput out(r);
  out.Write(NumberedFrame(0), 0, 0.0);
  EXPECT_THROW(out.Write(cv::Mat(10, 10, CV_8UC3), 1, 0.1), std::invalid_argument);
}

TEST(MergedLogReaderTest, EventsInTimestampOrderAcrossLogs) {
  const std::string dir = vtrack::testing::ScratchDir("viewer-merge");
  {
    lcm_util::LogWriter a(dir + "/a.lcm"), b(dir + "/b.lcm");
    const char x = 'x';
    for (std::int64_t t : {10, 30, 50, 50}) a.Write(t, "A", &x, 1);
    for (std::int64_t t : {5, 30, 40, 60}) b.Write(t, "B", &x, 1);
  }
  MergedLogReader r({dir + "/a.lcm", dir + "/b.lcm"});
  std::vector<std::pair<std::int64_t, std::string>> got;
  std::size_t source = 9;
  while (const auto* ev = r.Next(&source)) {
    got.emplace_back(ev->timestamp, ev->channel);
    EXPECT_EQ(source, ev->channel == "A" ? 0u : 1u);
  }
  const std::vector<std::pair<std::int64_t, std::string>> want = {
      {5, "B"}, {10, "A"}, {30, "A"}, {30, "B"}, {40, "B"}, {50, "A"}, {50, "A"}, {60, "B"}};
  EXPECT_EQ(got, want);
  EXPECT_EQ(r.BytesRead(), r.TotalBytes());
  EXPECT_TRUE(r.IncompleteLogs().empty());
  EXPECT_THROW(MergedLogReader({dir + "/missing.lcm"}), std::runtime_error);
}

TEST(LatestSlotTest, ReplacesUntakenItemsAndCountsThem) {
  LatestSlot<int> slot;
  EXPECT_FALSE(slot.Put(1));
  EXPECT_TRUE(slot.Put(2));
  EXPECT_TRUE(slot.Put(3));
  EXPECT_EQ(slot.Take(), 3);
  EXPECT_FALSE(slot.Put(4));
  slot.Close();
  EXPECT_FALSE(slot.Put(5));
  EXPECT_EQ(slot.Take(), 4);
  EXPECT_EQ(slot.Take(), std::nullopt);
  EXPECT_EQ(slot.dropped(), 2);
}

// The producer never waits for the consumer: while the consumer holds an item for a long time,
// the producer keeps putting; it gets the newest when it comes back.
TEST(LatestSlotTest, ProducerNeverWaitsForTheConsumer) {
  LatestSlot<int> slot;
  std::atomic<bool> consumer_busy{false}, release{false};
  std::vector<int> taken;
  std::thread consumer([&] {
    while (auto v = slot.Take()) {
      taken.push_back(*v);
      consumer_busy = true;
      while (!release) std::this_thread::yield();
    }
  });
  slot.Put(0);
  while (!consumer_busy) std::this_thread::yield();
  for (int i = 1; i <= 1000; ++i) slot.Put(i);  // would deadlock if Put waited for the consumer
  release = true;
  slot.Close();
  consumer.join();
  ASSERT_EQ(taken.size(), 2u);
  EXPECT_EQ(taken[0], 0);
  EXPECT_EQ(taken[1], 1000);
  EXPECT_EQ(slot.dropped(), 999);
}

TEST(WithReceiveBufferTest, AddsTheBufferOnlyToUdpmWithoutOne) {
  EXPECT_EQ(WithReceiveBuffer("udpm://239.255.76.67:7667?ttl=0"),
            "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(WithReceiveBuffer("udpm://239.255.76.67:7667"),
            "udpm://239.255.76.67:7667?recv_buf_size=4194304");
  EXPECT_EQ(WithReceiveBuffer("udpm://239.255.76.67:7667?recv_buf_size=8000000"),
            "udpm://239.255.76.67:7667?recv_buf_size=8000000");
  EXPECT_EQ(WithReceiveBuffer("memq://"), "memq://");
  EXPECT_EQ(WithReceiveBuffer("file:///tmp/x.lcm?speed=0"), "file:///tmp/x.lcm?speed=0");
  ::setenv("LCM_DEFAULT_URL", "udpm://239.255.76.67:7668?ttl=1", 1);
  EXPECT_EQ(WithReceiveBuffer(""), "udpm://239.255.76.67:7668?ttl=1&recv_buf_size=4194304");
  ::unsetenv("LCM_DEFAULT_URL");
  EXPECT_EQ(WithReceiveBuffer(""), "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
}

}  // namespace
}  // namespace vtrack::viewer
