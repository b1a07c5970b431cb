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

// Publishes poses at 100 Hz and 2 MB scans at 10 Hz from this process, in real time.
void PublishTraffic(lcm::LCM& lcm) {
  testing::RandomMessages r(7);
  ladar_scan_t scan = r.Scan(90000);
  pose_t pose = r.Pose();
  auto next = std::chrono::steady_clock::now();
  for (int i = 0; i < kPoses; ++i) {
    pose.utime = i * 10000;
    ASSERT_EQ(lcm.publish("EGO_POSE", &pose), 0);
    if (i % 10 == 0) {
      scan.seq = i / 10;
      scan.utime = pose.utime;
      ASSERT_EQ(lcm.publish("LADAR_SCAN", &scan), 0);
      // The same sweep as slices of one datagram each, in a burst, as the driver sends them.
      for (const ladar_slice_t& s : lcm_util::SliceSweep(scan, 0)) {
        ASSERT_EQ(lcm.publish("LADAR_SLICE", &s), 0);
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
  // Scans arrive complete: each one decodes to 90k points; and every slice was recorded, so
  // their sweeps join whole to the same returns (as a set: the random returns are in no
  // azimuth order, so slicing regroups them).
  std::map<std::int64_t, std::vector<float>> scan_x;
  lcm_util::SweepAssembler assembler;
  std::vector<lcm_util::AssembledSweep> sweeps;
  int slices = 0;
  for (const auto& e : recorded) {
    if (e.channel == "LADAR_SLICE") {
      ladar_slice_t s;
      ASSERT_GE(s.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
      EXPECT_LE(e.data.size(), static_cast<std::size_t>(lcm_util::kMaxDatagramMessageBytes));
      ++slices;
      assembler.Add(std::move(s), &sweeps);
    }
    if (e.channel != "LADAR_SCAN") continue;
    ladar_scan_t s;
    ASSERT_GE(s.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
    EXPECT_EQ(s.npoints, 90000);
    scan_x[s.seq] = s.x;
  }
  assembler.Flush(&sweeps);
  EXPECT_GT(slices, kScans * 30);
  EXPECT_EQ(assembler.slices_lost(), 0);
  ASSERT_EQ(sweeps.size(), static_cast<std::size_t>(kScans));
  for (auto& s : sweeps) {
    EXPECT_FALSE(s.partial()) << "sweep " << s.scan.seq;
    std::vector<float> a = s.scan.x, b = scan_x[s.scan.seq];
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    EXPECT_EQ(a, b) << "sweep " << s.scan.seq;
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

}  // namespace
}  // namespace vtrack
