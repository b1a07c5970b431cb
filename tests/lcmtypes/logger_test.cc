// lcm-logger records live traffic (including 2 MB scans at 10 Hz, and the same sweeps as bursts
// of slices of one datagram each); lcm-logplayer replays it to a
// subscriber that gets every message; reading the log through file://...?speed=0 gives the same
// events in the same order as reading the file directly. Runs in a private network namespace.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <thread>
#include <vector>

#include "lcmtypes/util/ladar_slices.h"
#include "lcmtypes/util/log_reader.h"
#include "tests/lcmtypes/random_messages.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"

namespace vtrack {
namespace {

using namespace std::chrono_literals;
using testing::Subprocess;

constexpr char kUrl[] = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";
constexpr int kScans = 20;   // 2 s of 2 MB scans at 10 Hz
constexpr int kPoses = 200;  // 100 Hz alongside

struct Event {
  std::string channel;
  std::string data;
  bool operator==(const Event&) const = default;
};

std::vector<Event> ReadWithLogReader(const std::string& path) {
  lcm_util::LogReader reader(path);
  std::vector<Event> out;
  while (const lcm::LogEvent* e = reader.Next()) {
    out.push_back({e->channel, std::string(static_cast<const char*>(e->data), e->datalen)});
  }
  return out;
}

struct Collector {
  std::vector<Event> events;
  void On(const lcm::ReceiveBuffer* b, const std::string& c) {
    events.push_back({c, std::string(static_cast<const char*>(b->data), b->data_size)});
  }
};

// Poses at 100 Hz and a 2 MB sweep at 10 Hz: whole on LADAR_SCAN, or (sliced) as slices of one
// datagram each on LADAR_SLICE, as the driver sends them.
void PublishTraffic(lcm::LCM& lcm, bool sliced = false) {
  testing::RandomMessages r(7);
  ladar_scan_t scan = r.Scan(90000);
  const std::vector<ladar_slice_t> slices = lcm_util::SliceSweep(scan, 0);
  pose_t pose = r.Pose();
  auto next = std::chrono::steady_clock::now();
  for (int i = 0; i < kPoses; ++i) {
    pose.utime = i * 10000;
    ASSERT_EQ(lcm.publish("EGO_POSE", &pose), 0);
    if (i % 10 == 0) {
      scan.seq = i / 10;
      scan.utime = pose.utime;
      if (!sliced) {
        ASSERT_EQ(lcm.publish("LADAR_SCAN", &scan), 0);
      }
      for (const ladar_slice_t& s : sliced ? slices : std::vector<ladar_slice_t>{}) {
        ladar_slice_t m = s;
        m.seq = scan.seq;
        m.utime = scan.utime;
        ASSERT_EQ(lcm.publish("LADAR_SLICE", &m), 0);
        std::this_thread::sleep_for(std::chrono::microseconds(lcm_util::kSliceGapUs));  // as the driver
      }
    }
    next += 10ms;
    std::this_thread::sleep_until(next);
  }
}

TEST(LcmLog, LoggerRecordsPlayerReplaysFileProviderAgrees) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = testing::ScratchDir("logger");
  const std::string log = dir + "/run.lcm";

  // 1. Record live traffic with lcm-logger.
  {
    Subprocess logger({"lcm-logger", "-q", "-f", std::string("--lcm-url=") + kUrl, log},
                      dir + "/logger.out");
    std::this_thread::sleep_for(700ms);  // logger subscribed
    ASSERT_TRUE(logger.Running()) << testing::ReadFile(dir + "/logger.out");
    lcm::LCM pub("udpm://239.255.76.67:7667?ttl=0");
    ASSERT_TRUE(pub.good());
    PublishTraffic(pub);
    std::this_thread::sleep_for(500ms);  // last datagrams written
    logger.Signal(SIGINT);
    auto st = logger.Wait(5000ms);
    ASSERT_TRUE(st.has_value()) << "lcm-logger did not stop on SIGINT";
  }
  const std::vector<Event> recorded = ReadWithLogReader(log);
  int scans = 0, poses = 0;
  for (const auto& e : recorded) {
    scans += e.channel == "LADAR_SCAN";
    poses += e.channel == "EGO_POSE";
  }
  EXPECT_EQ(scans, kScans);
  EXPECT_EQ(poses, kPoses);
  // Scans arrive complete: each one decodes to 90k points.
  for (const auto& e : recorded) {
    if (e.channel != "LADAR_SCAN") continue;
    ladar_scan_t s;
    ASSERT_GE(s.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
    EXPECT_EQ(s.npoints, 90000);
  }

  // 2. lcm-logplayer replays it to a subscriber that gets every message, in order.
  {
    lcm::LCM sub(kUrl);
    ASSERT_TRUE(sub.good());
    Collector got;
    // Slices come in bursts of ~33: more than LCM's default queue of 30 per subscription.
    sub.subscribe(".*", &Collector::On, &got)->setQueueCapacity(lcm_util::kSliceQueueCapacity);
    Subprocess player({"lcm-logplayer", std::string("--lcm-url=") + kUrl, log},
                      dir + "/player.out");
    const auto deadline = std::chrono::steady_clock::now() + 15s;
    while (got.events.size() < recorded.size() && std::chrono::steady_clock::now() < deadline) {
      sub.handleTimeout(100);
    }
    while (sub.handleTimeout(300) > 0) {}
    player.Wait(5000ms);
    EXPECT_EQ(got.events.size(), recorded.size());
    EXPECT_TRUE(got.events == recorded) << "replayed events differ from the recorded ones";
  }

  // 3. The file provider at speed=0 (lossless, as fast as possible) gives the same events in the
  //    same order as reading the file.
  {
    lcm::LCM file("file://" + log + "?speed=0");
    ASSERT_TRUE(file.good());
    Collector got;
    file.subscribe(".*", &Collector::On, &got);
    while (file.handle() == 0) {}
    EXPECT_TRUE(got.events == recorded);
  }
}

// The same traffic with each sweep sent as ~33 slices of one datagram, kSliceGapUs apart as the
// driver sends them (back to back, lcm-logger lost 30 % of the poses and slices): lcm-logger
// records every slice, the sweeps join whole (their returns as a set: the random returns are in
// no azimuth order, so slicing regroups them), and lcm-logplayer replays every slice.
TEST(LcmLog, LoggerRecordsEverySliceOfSweepsAt10Hz) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = testing::ScratchDir("logger-slices");
  const std::string log = dir + "/run.lcm";
  {
    Subprocess logger({"lcm-logger", "-q", "-f", std::string("--lcm-url=") + kUrl, log},
                      dir + "/logger.out");
    std::this_thread::sleep_for(700ms);
    ASSERT_TRUE(logger.Running()) << testing::ReadFile(dir + "/logger.out");
    lcm::LCM pub("udpm://239.255.76.67:7667?ttl=0");
    ASSERT_TRUE(pub.good());
    PublishTraffic(pub, /*sliced=*/true);
    std::this_thread::sleep_for(500ms);
    logger.Signal(SIGINT);
    ASSERT_TRUE(logger.Wait(5000ms).has_value()) << "lcm-logger did not stop on SIGINT";
  }
  testing::RandomMessages r(7);
  std::vector<float> published_x = r.Scan(90000).x;  // the returns every sweep carries
  std::sort(published_x.begin(), published_x.end());
  const std::vector<Event> recorded = ReadWithLogReader(log);
  lcm_util::SweepAssembler assembler;
  std::vector<lcm_util::AssembledSweep> sweeps;
  int slices = 0, poses = 0;
  for (const auto& e : recorded) {
    poses += e.channel == "EGO_POSE";
    if (e.channel != "LADAR_SLICE") continue;
    ladar_slice_t s;
    ASSERT_GE(s.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
    EXPECT_LE(e.data.size(), static_cast<std::size_t>(lcm_util::kMaxDatagramMessageBytes));
    ++slices;
    assembler.Add(std::move(s), &sweeps);
  }
  assembler.Flush(&sweeps);
  EXPECT_EQ(poses, kPoses);
  EXPECT_GT(slices, kScans * 30);
  EXPECT_EQ(assembler.slices_lost(), 0);
  ASSERT_EQ(sweeps.size(), static_cast<std::size_t>(kScans));
  for (auto& s : sweeps) {
    EXPECT_FALSE(s.partial()) << "sweep " << s.scan.seq;
    std::vector<float> x = s.scan.x;
    std::sort(x.begin(), x.end());
    EXPECT_EQ(x, published_x) << "sweep " << s.scan.seq;
  }
  // Replayed: a subscriber with room for a burst gets every message.
  lcm::LCM sub(kUrl);
  ASSERT_TRUE(sub.good());
  Collector got;
  sub.subscribe(".*", &Collector::On, &got)->setQueueCapacity(lcm_util::kSliceQueueCapacity);
  Subprocess player({"lcm-logplayer", std::string("--lcm-url=") + kUrl, log}, dir + "/player.out");
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  while (got.events.size() < recorded.size() && std::chrono::steady_clock::now() < deadline) {
    sub.handleTimeout(100);
  }
  player.Wait(5000ms);
  EXPECT_TRUE(got.events == recorded) << got.events.size() << " of " << recorded.size();
}

}  // namespace
}  // namespace vtrack
