// vtrack-monitor: decoded summaries, rates and bandwidth from known message streams, and the
// tool on a log file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "lcmtypes/util/log_reader.h"
#include "log_tools/monitor/monitor.h"
#include "tests/log_tools/synthetic_run.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "vtrack/detection_list_t.hpp"
#include "vtrack/pose_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack::monitor {
namespace {

template <class T>
std::string Encode(const T& msg) {
  std::string b(static_cast<std::size_t>(msg.getEncodedSize()), '\0');
  msg.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

vtrack::pose_t Pose(double x, double y, double yaw_deg) {
  vtrack::pose_t p{};
  p.pos[0] = x;
  p.pos[1] = y;
  const double h = yaw_deg * M_PI / 360.0;
  p.orientation[0] = std::cos(h);
  p.orientation[3] = std::sin(h);
  p.vel[0] = 3.0;
  p.vel[1] = 4.0;
  return p;
}

TEST(MonitorTest, DescribesEachType) {
  const std::string pose = Encode(Pose(1.0, 2.0, 30.0));
  Description d = Describe(pose.data(), pose.size());
  EXPECT_TRUE(d.ok);
  EXPECT_EQ(d.type, "pose_t");
  EXPECT_NE(d.summary.find("pos (1.00, 2.00, 0.00) m"), std::string::npos) << d.summary;
  EXPECT_NE(d.summary.find("yaw 30.0 deg"), std::string::npos) << d.summary;
  EXPECT_NE(d.summary.find("speed 5.00 m/s"), std::string::npos) << d.summary;

  const auto tracks = vtrack::testing::SyntheticTracks("mht");
  const std::string tl = Encode(tracks[0]);
  d = Describe(tl.data(), tl.size());
  EXPECT_EQ(d.type, "track_list_t");
  // Synthetic tracks: 6 confirmed, 1 tentative, 6 vehicles (3 is CLASS_OTHER).
  EXPECT_NE(d.summary.find("mht: 7 tracks (6 confirmed, 1 tentative, 0 coasting; 6 vehicles)"),
            std::string::npos) << d.summary;

  const auto truth = vtrack::testing::SyntheticTruth();
  const std::string ol = Encode(truth[1]);
  d = Describe(ol.data(), ol.size());
  EXPECT_EQ(d.type, "object_list_t");
  EXPECT_NE(d.summary.find("4 objects (2 vehicles in labelled region)"), std::string::npos) << d.summary;

  vtrack::tracker_status_t st{};
  st.mode = "ism";
  st.scans_received = 10;
  st.scans_processed = 9;
  st.scans_dropped = 1;
  st.num_reasons = 1;
  st.reject_reason = {"nan_point"};
  st.reject_count = {4};
  const std::string sb = Encode(st);
  d = Describe(sb.data(), sb.size());
  EXPECT_NE(d.summary.find("scans 10 recv / 9 proc / 1 drop"), std::string::npos) << d.summary;
  EXPECT_NE(d.summary.find("nan_point 4"), std::string::npos) << d.summary;

  vtrack::detection_list_t boxes{};
  boxes.seq = 17;
  boxes.source = "pointrcnn";
  boxes.num_detections = 2;
  boxes.detections.resize(2);
  boxes.detections[0].score = 0.5f;
  boxes.detections[1].score = 0.75f;
  for (auto& b : boxes.detections) b.length = b.width = b.height = 1.0;
  const std::string db = Encode(boxes);
  d = Describe(db.data(), db.size());
  EXPECT_TRUE(d.ok);
  EXPECT_EQ(d.type, "detection_list_t");
  EXPECT_NE(d.summary.find("pointrcnn: 2 boxes (best score 0.75), frame 17"), std::string::npos)
      << d.summary;
  EXPECT_EQ(TypeName(vtrack::detection_list_t::getHash()), "detection_list_t");
}

TEST(MonitorTest, BadMessagesSayWhy) {
  std::string tl = Encode(vtrack::testing::SyntheticTracks("mht")[0]);
  tl.resize(tl.size() / 2);  // truncated
  Description d = Describe(tl.data(), tl.size());
  EXPECT_FALSE(d.ok);
  EXPECT_EQ(d.type, "track_list_t");
  EXPECT_NE(d.summary.find("cannot decode"), std::string::npos) << d.summary;
  d = Describe("abc", 3);
  EXPECT_FALSE(d.ok);
  const std::string foreign = "0123456789abcdef";
  d = Describe(foreign.data(), foreign.size());
  EXPECT_TRUE(d.ok);  // another package's type is not an error
  EXPECT_EQ(d.type.rfind("? 0x", 0), 0u) << d.type;
}

TEST(MonitorTest, RatesAndBandwidth) {
  const std::string pose = Encode(Pose(0, 0, 0));
  std::string bad = pose;
  bad.resize(20);
  ChannelTable table(2.0);
  // 11 messages at 10 Hz over 1 s on EGO_POSE; 3 at 1 Hz on BAD (one truncated).
  for (int i = 0; i <= 10; ++i) table.Add("EGO_POSE", i * 100'000, pose.data(), pose.size());
  table.Add("BAD", 0, pose.data(), pose.size());
  table.Add("BAD", 1'000'000, bad.data(), bad.size());
  // Log mode: (count - 1) / span; bandwidth = mean size x rate.
  auto rows = table.Rows(1'000'000, true);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].channel, "BAD");
  EXPECT_EQ(rows[0].decode_errors, 1);
  EXPECT_FALSE(rows[0].summary.find("cannot decode") == std::string::npos) << rows[0].summary;
  EXPECT_EQ(rows[1].count, 11);
  EXPECT_NEAR(rows[1].rate_hz, 10.0, 1e-9);
  EXPECT_NEAR(rows[1].bandwidth_bps, 10.0 * pose.size(), 1e-6);
  // Live mode: 20 Hz for 5 s, a 2 s window: 40 messages in (3, 5] (and the one at 3.0 s).
  ChannelTable live(2.0);
  for (int i = 0; i <= 100; ++i) live.Add("P", i * 50'000, pose.data(), pose.size());
  rows = live.Rows(5'000'000, false);
  EXPECT_NEAR(rows[0].rate_hz, 41.0 / 2.0, 1e-9);
  const std::string text = live.Render(5'000'000, false, 60);
  EXPECT_NE(text.find("channel"), std::string::npos);
  for (std::size_t a = 0, b; (b = text.find('\n', a)) != std::string::npos; a = b + 1) {
    EXPECT_LE(b - a, 60u);
  }
}

TEST(MonitorCliTest, SummarisesALog) {
  const std::string exe = vtrack::testing::BinDir() + "/vtrack-monitor";
  if (!std::filesystem::exists(exe)) GTEST_SKIP() << exe << " is not built";
  const std::string dir = vtrack::testing::ScratchDir("monitor_cli");
  vtrack::testing::WriteSyntheticRun(dir + "/run.lcm");
  const std::string out = dir + "/out.txt";
  ASSERT_EQ(vtrack::testing::RunCommand({exe, "--input", dir + "/run.lcm", "--width", "0"}, out), 0)
      << vtrack::testing::ReadFile(out);
  const std::string text = vtrack::testing::ReadFile(out);
  // GROUND_TRUTH and EGO_POSE: kScans + 1 messages over 8.9 s (-1 s, then 0 .. 7.9 s).
  for (const char* s : {"GROUND_TRUTH", "object_list_t", "EGO_POSE", "pose_t", "LADAR_SCAN",
                        "ladar_scan_t", "sim:synthetic: 4 objects"}) {
    EXPECT_NE(text.find(s), std::string::npos) << s << "\n" << text;
  }
  char rate[32];
  std::snprintf(rate, sizeof(rate), "%.1f", vtrack::testing::kScans / 8.9);
  EXPECT_NE(text.find(rate), std::string::npos) << rate << "\n" << text;

  EXPECT_EQ(vtrack::testing::RunCommand({exe, "--interval", "0"}, out), 2);
  EXPECT_NE(vtrack::testing::ReadFile(out).find("--interval must be > 0"), std::string::npos);
  EXPECT_EQ(vtrack::testing::RunCommand({exe, "--input", dir + "/none.lcm"}, out), 1);
  // A log named without --input would be ignored and the monitor would go live: refused.
  EXPECT_EQ(vtrack::testing::RunCommand({exe, dir + "/run.lcm"}, out, std::chrono::seconds(30)), 2);
  EXPECT_NE(vtrack::testing::ReadFile(out).find("unexpected argument '" + dir + "/run.lcm'"),
            std::string::npos)
      << vtrack::testing::ReadFile(out);
  EXPECT_EQ(vtrack::testing::RunCommand({exe, "--help"}, out), 0);
}

}  // namespace
}  // namespace vtrack::monitor
