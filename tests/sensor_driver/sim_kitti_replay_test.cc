// The --kitti source of vtrack-ladar-driver and vtrack-ego-pose, live on udpm:// in a private
// network namespace: the logged scans, ground truth and poses are, byte for byte, the KITTI
// reader's (sensor_driver/kitti) moved to the run's start time. Skips without the real data.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "lcmtypes/util/log_reader.h"
#include "lcmtypes/util/process.h"
#include "sensor_driver/kitti/kitti_sequence.h"
#include "tests/support/lcm_log.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"

namespace vtrack {
namespace {

using namespace std::chrono_literals;
using testing::BinDir;
using testing::KittiDir;
using testing::kTestBusUrl;
using testing::ScratchDir;

constexpr char kLoggerUrl[] = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=16777216";

template <class T>
std::string Encode(const T& m) {
  std::string b(m.getEncodedSize(), '\0');
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// A folder of the boxes layout has no point clouds: the driver refuses it before its first lap
// (a file:// URL: nothing goes on a bus).
TEST(KittiReplayTest, DriverRefusesASequenceWithoutPointClouds) {
  const std::string boxes = testing::DataDir() + "/kitti_tracking_boxes";
  if (!std::filesystem::is_directory(boxes)) GTEST_SKIP() << boxes << " not found: skipped";
  const std::string dir = ScratchDir("kitti_driver_boxes");
  const int rc = testing::RunCommand(
      {BinDir() + "/vtrack-ladar-driver", "--lcm-url", "file://" + dir + "/l.lcm?mode=w", "--kitti",
       boxes, "--sequence", "0017", "--stop-after", "2"},
      dir + "/driver.txt", std::chrono::seconds(60));
  const std::string out = testing::ReadFile(dir + "/driver.txt");
  EXPECT_EQ(rc, 1) << out;
  EXPECT_NE(out.find("has no Velodyne point clouds"), std::string::npos) << out;
}

TEST(KittiReplayTest, DriverAndEgoPosePublishTheSequenceOnTheRunClock) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  if (KittiDir().empty()) GTEST_SKIP() << "no KITTI data at " << testing::DataDir();
  const std::string dir = ScratchDir("sim_kitti_replay");
  // The point clouds are unpacked once per build tree (shared with the KITTI readers' tests);
  // doing it here first lets the processes start on time.
  const std::string cache = BinDir() + "/../kitti_cache";
  kitti::SequenceOptions opt;
  opt.dir = KittiDir();
  opt.cache_dir = cache;
  opt.sink = [](const std::string&) {};
  const kitti::Sequence seq(opt);

  const std::int64_t start = (lcm_util::WallUtime() / 1000 + 3000) * 1000;
  // 3.5 s of the run after the 3 s wait, in slow motion in a sanitized build (LiveRate()): the
  // same messages, later.
  const double rate = testing::LiveRate();
  const std::vector<std::string> common{"--kitti", KittiDir(), "--cache-dir", cache,
                                        "--start-utime", std::to_string(start), "--laps", "1",
                                        "--stop-after", std::to_string(3.0 + 3.5 / rate),
                                        "--rate", std::to_string(rate), "--lcm-url", kTestBusUrl,
                                        "-q"};
  const std::string log = dir + "/live.lcm";
  // Whole sweeps (--slices 0): the bytes of each must be the converter's ladar_scan_t.
  testing::RecordDriverAndEgoPose(dir, common, kLoggerUrl, log, 60000ms, 700ms, {"--slices", "0"});
  ASSERT_FALSE(HasFatalFailure());
  const std::int64_t shift = start - seq.ScanUtime(0);
  int scans = 0, truths = 0, poses = 0;
  lcm_util::LogReader r(log);
  while (const lcm::LogEvent* ev = r.Next()) {
    const std::string data(static_cast<const char*>(ev->data), static_cast<std::size_t>(ev->datalen));
    if (ev->channel == "LADAR_SCAN") {
      ladar_scan_t expected = seq.Scan(scans);
      expected.utime += shift;
      ASSERT_TRUE(Encode(expected) == data) << "scan " << scans;
      ++scans;
    } else if (ev->channel == "GROUND_TRUTH") {
      object_list_t expected = seq.GroundTruth(truths);
      expected.utime += shift;
      ASSERT_TRUE(Encode(expected) == data) << "ground truth " << truths;
      ++truths;
    } else if (ev->channel == "EGO_POSE") {
      const std::int64_t offset = poses * 10000LL;  // 100 Hz
      pose_t expected = seq.PoseAt(seq.ScanUtime(0) + offset);
      expected.utime = start + offset;
      ASSERT_TRUE(Encode(expected) == data) << "pose " << poses;
      ++poses;
    }
  }
  // 3.5 s of the run were published: every frame (10 Hz) and pose (100 Hz) in that time.
  EXPECT_GE(scans, 33);
  EXPECT_EQ(truths, scans);
  EXPECT_GE(poses, 340);
}

}  // namespace
}  // namespace vtrack
