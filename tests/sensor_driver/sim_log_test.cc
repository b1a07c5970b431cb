// vtrack-sim-log, run as a process: deterministic logs, every channel at its rate without gaps,
// event timestamps as a live run publishes, ground truth that agrees with the returns, and clear
// errors for bad options and files.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "tests/support/lcm_log.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "base/angle.h"
#include "base/pose.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"

namespace vtrack {
namespace {

using testing::BinDir;
using testing::LoggedEvent;
using testing::ReadFile;
using testing::ReadLogEvents;
using testing::RunCommand;
using testing::ScratchDir;

int SimLog(const std::vector<std::string>& args, const std::string& log) {
  std::vector<std::string> argv{BinDir() + "/vtrack-sim-log"};
  argv.insert(argv.end(), args.begin(), args.end());
  return RunCommand(argv, log);
}

template <class T>
T DecodeOrDie(const LoggedEvent& e) {
  T m;
  std::string why;
  const auto err = lcm_util::Decode(e.data.data(), e.data.size(), &m, &why);
  EXPECT_EQ(err, lcm_util::DecodeError::kNone) << e.channel << ": " << why;
  return m;
}

TEST(SimLogTest, SameSeedGivesAByteIdenticalLog) {
  const std::string dir = ScratchDir("sim_log_seed");
  // Figure 6 draws everywhere: range noise, dropouts, spurious returns, bush depths, pose noise.
  auto run = [&](const std::string& out, const std::string& seed, const std::string& sensor) {
    // 3 s of the single-plane sensor (75 scans), 0.5 s of the 64-layer one (4 scans, 11 MB).
    return SimLog({"--scenario", "paper_fig6_noisy_follow", "--duration",
                   sensor == "velodyne64" ? "0.5" : "3", "--seed", seed, "--sensor", sensor,
                   "--out", dir + "/" + out, "-q"},
                  dir + "/" + out + ".txt");
  };
  for (const std::string sensor : {"single_plane", "velodyne64"}) {
    ASSERT_EQ(run("a.lcm", "3", sensor), 0) << ReadFile(dir + "/a.lcm.txt");
    ASSERT_EQ(run("b.lcm", "3", sensor), 0);
    ASSERT_EQ(run("c.lcm", "4", sensor), 0);
    const std::string a = ReadFile(dir + "/a.lcm"), b = ReadFile(dir + "/b.lcm"),
                      c = ReadFile(dir + "/c.lcm");
    EXPECT_GT(a.size(), 100000u) << sensor;
    EXPECT_TRUE(a == b) << sensor << ": same seed, different bytes";
    EXPECT_FALSE(a == c) << sensor << ": another seed gave the same log";
  }
}

// Scans at the sensor rate with consecutive seq, one ground-truth list per scan, poses at 100 Hz,
// no gaps; event timestamps at the instant of publication and in order.
TEST(SimLogTest, EveryChannelAtItsRateWithoutGaps) {
  const std::string dir = ScratchDir("sim_log_rates");
  const std::string log = dir + "/run.lcm";
  ASSERT_EQ(SimLog({"--scenario", "paper_fig5_follow_clutter", "--duration", "6", "--start-utime",
                    "1600000000000000", "--out", log},
                   dir + "/out.txt"),
            0)
      << ReadFile(dir + "/out.txt");
  EXPECT_NE(ReadFile(dir + "/out.txt").find("real time"), std::string::npos);
  const auto events = ReadLogEvents(log);
  std::vector<ladar_scan_t> scans;
  std::vector<object_list_t> truths;
  std::vector<pose_t> poses;
  std::int64_t last_ts = 0;
  for (const LoggedEvent& e : events) {
    EXPECT_GE(e.timestamp, last_ts);
    last_ts = e.timestamp;
    if (e.channel == "LADAR_SCAN") {
      scans.push_back(DecodeOrDie<ladar_scan_t>(e));
      EXPECT_EQ(e.timestamp, scans.back().utime + scans.back().sweep_duration_us);
    } else if (e.channel == "GROUND_TRUTH") {
      truths.push_back(DecodeOrDie<object_list_t>(e));
      ASSERT_FALSE(scans.empty());
      EXPECT_EQ(e.timestamp, scans.back().utime + scans.back().sweep_duration_us);
    } else if (e.channel == "EGO_POSE") {
      poses.push_back(DecodeOrDie<pose_t>(e));
      EXPECT_EQ(e.timestamp, poses.back().utime);
    } else {
      ADD_FAILURE() << "unexpected channel " << e.channel;
    }
  }
  // 6 s at 25 Hz; poses 0 .. 5.99 s at 100 Hz; each sweep lies within the poses.
  ASSERT_EQ(poses.size(), 600u);
  ASSERT_EQ(scans.size(), 150u);
  ASSERT_EQ(truths.size(), scans.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_EQ(poses[k].utime, 1600000000000000 + static_cast<std::int64_t>(k) * 10000);
  }
  for (std::size_t i = 0; i < scans.size(); ++i) {
    EXPECT_EQ(scans[i].seq, static_cast<std::int64_t>(i));
    EXPECT_EQ(scans[i].utime, 1600000000000000 + static_cast<std::int64_t>(i) * 40000);
    EXPECT_EQ(truths[i].utime, scans[i].utime);
    EXPECT_EQ(truths[i].scan_seq, scans[i].seq);
    EXPECT_EQ(truths[i].source, "sim:paper_fig5_follow_clutter");
    EXPECT_LE(scans[i].utime + scans[i].sweep_duration_us, poses.back().utime);
    EXPECT_EQ(scans[i].sensor_id, "single_plane");
    EXPECT_EQ(scans[i].num_rings, 1);
  }
}

// A pose rate too low for the last sweeps (6 s at 25 Hz, poses at 2 Hz: the last pose at 5.5 s)
// leaves them out, as the tracker could not place their returns, and says how many; the default
// rate leaves none out and says nothing.
TEST(SimLogTest, SweepsLeftOutByALowPoseRateAreCountedInAWarning) {
  const std::string dir = ScratchDir("sim_log_low_pose_rate");
  const std::string log = dir + "/run.lcm";
  const std::int64_t start = 1600000000000000;
  ASSERT_EQ(SimLog({"--scenario", "paper_fig5_follow_clutter", "--duration", "6", "--pose-rate",
                    "2", "--start-utime", std::to_string(start), "--out", log, "-q"},
                   dir + "/out.txt"),
            0)
      << ReadFile(dir + "/out.txt");
  int scans = 0;
  std::int64_t last_pose = 0, last_sweep_end = 0, sweep_us = 0;
  for (const LoggedEvent& e : ReadLogEvents(log)) {
    if (e.channel == "LADAR_SCAN") {
      const auto scan = DecodeOrDie<ladar_scan_t>(e);
      last_sweep_end = scan.utime + scan.sweep_duration_us;
      sweep_us = scan.sweep_duration_us;
      ++scans;
    } else if (e.channel == "EGO_POSE") {
      last_pose = DecodeOrDie<pose_t>(e).utime;
    }
  }
  ASSERT_GT(scans, 0);
  EXPECT_EQ(last_pose, start + 5500000);
  // Every sweep that ends by the last pose is logged, and no other.
  EXPECT_LE(last_sweep_end, last_pose);
  EXPECT_GT(start + scans * 40000 + sweep_us, last_pose);
  // The sweeps of 6 s at 25 Hz that end by the last whole millisecond (150), less those logged.
  const std::string said = ReadFile(dir + "/out.txt");
  EXPECT_NE(said.find("warning: " + std::to_string(150 - scans) + " of the scenario's 150 sweeps "
                      "are left out"),
            std::string::npos)
      << said;

  ASSERT_EQ(SimLog({"--scenario", "paper_fig5_follow_clutter", "--duration", "6", "--out", log,
                    "-q"},
                   dir + "/out.txt"),
            0);
  EXPECT_EQ(ReadFile(dir + "/out.txt"), "");

  // Live, vtrack-ego-pose at that rate (memq://: no network) warns of the same sweeps, which the
  // driver, following the scenario's rate, still publishes; at the scenario's rate it does not.
  const auto ego_pose = [&](const std::vector<std::string>& rate) {
    std::vector<std::string> argv{BinDir() + "/vtrack-ego-pose", "--scenario",
                                  "paper_fig5_follow_clutter", "--duration", "6", "--lcm-url",
                                  "memq://", "--stop-after", "0.2", "-q"};
    argv.insert(argv.end(), rate.begin(), rate.end());
    EXPECT_EQ(RunCommand(argv, dir + "/ego.txt"), 0) << ReadFile(dir + "/ego.txt");
    return ReadFile(dir + "/ego.txt");
  };
  const std::string low = ego_pose({"--pose-rate", "2"});
  EXPECT_NE(low.find("vtrack-ego-pose: warning: " + std::to_string(150 - scans) +
                     " of the scenario's 150 sweeps cannot be tracked"),
            std::string::npos)
      << low;
  EXPECT_NE(low.find("a higher --pose-rate"), std::string::npos) << low;
  const std::string usual = ego_pose({});
  EXPECT_EQ(usual.find("warning"), std::string::npos) << usual;
}

Eigen::Isometry3d PoseOf(const pose_t& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(p.orientation[0], p.orientation[1], p.orientation[2],
                                  p.orientation[3]).toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.pos[0], p.pos[1], p.pos[2]);
  return T;
}

// num_points of every object equals the returns that fall in its box (at each return's time),
// found here by placing every return in the world with the log's own poses; in_labelled_region
// follows its definition; vx, vy and yaw_rate match finite differences of the truth.
TEST(SimLogTest, GroundTruthAgreesWithTheReturns) {
  const std::string dir = ScratchDir("sim_log_truth");
  const std::string log = dir + "/run.lcm";
  ASSERT_EQ(SimLog({"--scenario", "urban_intersection", "--sensor", "single_plane", "--duration",
                    "12", "--out", log, "-q"},
                   dir + "/out.txt"),
            0)
      << ReadFile(dir + "/out.txt");
  PoseHistory history(100'000'000);
  std::vector<ladar_scan_t> scans;
  std::vector<object_list_t> truths;
  for (const LoggedEvent& e : ReadLogEvents(log)) {
    if (e.channel == "EGO_POSE") {
      const pose_t p = DecodeOrDie<pose_t>(e);
      history.Add(p.utime, PoseOf(p));
    } else if (e.channel == "LADAR_SCAN") {
      scans.push_back(DecodeOrDie<ladar_scan_t>(e));
    } else if (e.channel == "GROUND_TRUTH") {
      truths.push_back(DecodeOrDie<object_list_t>(e));
    }
  }
  ASSERT_EQ(scans.size(), truths.size());
  ASSERT_GT(scans.size(), 250u);
  int checked_moving = 0, labelled = 0, total_ambiguous = 0, total_returns = 0;
  for (std::size_t i = 0; i < scans.size(); i += 7) {
    const ladar_scan_t& s = scans[i];
    const object_list_t& g = truths[i];
    Eigen::Isometry3d body_from_sensor = Eigen::Isometry3d::Identity();
    body_from_sensor.linear() = Eigen::Quaterniond(s.sensor_orientation[0], s.sensor_orientation[1],
                                                   s.sensor_orientation[2], s.sensor_orientation[3])
                                    .toRotationMatrix();
    body_from_sensor.translation() = Eigen::Vector3d(s.sensor_pos[0], s.sensor_pos[1], s.sensor_pos[2]);
    // Each return is attributed to the one object whose box (grown by a noise margin) holds it;
    // a return within the margin of two objects (where walls meet in a corner) is ambiguous and
    // only bounds the counts.
    std::map<std::int64_t, int> counted, ambiguous;
    for (int k = 0; k < s.npoints; ++k) {
      const auto pose = history.At(s.utime + s.dt_us[k], 0);
      ASSERT_TRUE(pose.has_value());
      const Eigen::Vector3d w = *pose * body_from_sensor * Eigen::Vector3d(s.x[k], s.y[k], s.z[k]);
      const double dt = s.dt_us[k] * 1e-6;
      std::vector<std::int64_t> holders;
      for (const object_t& o : g.objects) {
        // The box at the return's time, moved on from the scan's start by its velocity and yaw
        // rate (a 20 ms sweep: the neglected curvature is far below a millimetre).
        const Eigen::Vector2d c(o.x + o.vx * dt, o.y + o.vy * dt);
        const double yaw = o.yaw + o.yaw_rate * dt;
        const Eigen::Vector2d d = w.head<2>() - c;
        const double along = d.x() * std::cos(yaw) + d.y() * std::sin(yaw);
        const double across = -d.x() * std::sin(yaw) + d.y() * std::cos(yaw);
        const double margin = 0.1;  // 5 sigma of the 2 cm range noise
        if (std::abs(along) <= 0.5 * o.length + margin && std::abs(across) <= 0.5 * o.width + margin &&
            w.z() <= o.height + margin) {
          holders.push_back(o.id);
        }
      }
      ASSERT_FALSE(holders.empty()) << "a return on no object: scan " << s.seq << " point " << k;
      if (holders.size() == 1) {
        ++counted[holders[0]];
      } else {
        for (auto id : holders) ++ambiguous[id];
        ++total_ambiguous;
      }
      ++total_returns;
    }
    const Eigen::Vector3d sensor = (*history.At(s.utime, 0) * body_from_sensor).translation();
    for (const object_t& o : g.objects) {
      EXPECT_GE(o.num_points, counted[o.id]) << "object " << o.id << " in scan " << s.seq;
      EXPECT_LE(o.num_points, counted[o.id] + ambiguous[o.id]) << "object " << o.id << " in scan " << s.seq;
      const bool in = std::hypot(o.x - sensor.x(), o.y - sensor.y()) <= 50.0 && o.num_points >= 5;
      EXPECT_EQ(o.in_labelled_region, in) << "object " << o.id;
      labelled += o.in_labelled_region;
      checked_moving += o.moving && o.num_points > 0;
    }
  }
  EXPECT_LT(total_ambiguous, 0.02 * total_returns);  // building corners: a return or two a scan
  EXPECT_GT(checked_moving, 20);
  EXPECT_GT(labelled, 100);

  // Velocities against central differences of the truth over neighbouring scans (40 ms apart).
  for (std::size_t i = 1; i + 1 < truths.size(); i += 11) {
    const double h = (truths[i + 1].utime - truths[i - 1].utime) * 1e-6;
    for (std::size_t n = 0; n < truths[i].objects.size(); ++n) {
      const object_t &a = truths[i - 1].objects[n], &b = truths[i + 1].objects[n], &o = truths[i].objects[n];
      ASSERT_EQ(a.id, o.id);
      EXPECT_NEAR(o.vx, (b.x - a.x) / h, 0.05) << o.id;
      EXPECT_NEAR(o.vy, (b.y - a.y) / h, 0.05) << o.id;
      EXPECT_NEAR(o.yaw_rate, AngleDiff(b.yaw, a.yaw) / h, 0.02) << o.id;
      if (o.object_class == object_t::CLASS_POLE) {
        EXPECT_TRUE(std::isnan(o.rear_axle_offset));
      }
      if (o.object_class == object_t::CLASS_CAR) {
        EXPECT_LT(o.rear_axle_offset, 0.0);
      }
    }
  }
}

TEST(SimLogTest, CommandLineErrorsAreClear) {
  const std::string dir = ScratchDir("sim_log_cli");
  EXPECT_EQ(SimLog({"--help"}, dir + "/help.txt"), 0);
  EXPECT_NE(ReadFile(dir + "/help.txt").find("--scenario"), std::string::npos);
  EXPECT_EQ(SimLog({}, dir + "/none.txt"), 2);
  EXPECT_NE(ReadFile(dir + "/none.txt").find("--scenario is required"), std::string::npos);
  EXPECT_EQ(SimLog({"--scenario", "stress", "--out", dir + "/x.lcm", "--bogus"}, dir + "/bogus.txt"), 2);
  EXPECT_NE(ReadFile(dir + "/bogus.txt").find("bogus"), std::string::npos);
  EXPECT_EQ(SimLog({"--scenario", "no_such_scenario", "--out", dir + "/x.lcm"}, dir + "/name.txt"), 1);
  EXPECT_NE(ReadFile(dir + "/name.txt").find("no scenario 'no_such_scenario'"), std::string::npos);
  EXPECT_EQ(SimLog({"--scenario", "stress", "--out", dir + "/x.lcm", "--dropout", "1.5"}, dir + "/drop.txt"), 1);
  EXPECT_NE(ReadFile(dir + "/drop.txt").find("dropout = 1.5"), std::string::npos);
  EXPECT_EQ(SimLog({"--scenario", "stress", "--out", dir + "/x.lcm", "--sensor", "lidar9"}, dir + "/sensor.txt"), 1);
  EXPECT_NE(ReadFile(dir + "/sensor.txt").find("no sensor 'lidar9'"), std::string::npos);
  // Each available sensor named once (the scenario's own and the presets overlap).
  const std::string sensors = ReadFile(dir + "/sensor.txt");
  const auto first = sensors.find("velodyne64");
  ASSERT_NE(first, std::string::npos) << sensors;
  EXPECT_EQ(sensors.find("velodyne64", first + 1), std::string::npos) << sensors;
  std::ofstream(dir + "/bad.yaml") << "duration: 10\nsensor: single_plane\nego:\n  start: {x: 0, yy: 0}\n";
  EXPECT_EQ(SimLog({"--scenario", dir + "/bad.yaml", "--out", dir + "/x.lcm"}, dir + "/bad.txt"), 1);
  EXPECT_NE(ReadFile(dir + "/bad.txt").find(dir + "/bad.yaml:4:"), std::string::npos) << ReadFile(dir + "/bad.txt");
  EXPECT_NE(ReadFile(dir + "/bad.txt").find("ego.start.yy: unknown key"), std::string::npos);
  EXPECT_EQ(SimLog({"--scenario", "stress", "--out", "/nonexistent/dir/x.lcm"}, dir + "/out.txt"), 1);
  EXPECT_NE(ReadFile(dir + "/out.txt").find("/nonexistent/dir/x.lcm"), std::string::npos);
  // A start time past 2^53 us would overflow the log's times a few seconds in: refused.
  EXPECT_EQ(SimLog({"--scenario", "stress", "--out", dir + "/x.lcm", "--start-utime",
                    "9223372036854775807"}, dir + "/late.txt"), 2);
  EXPECT_NE(ReadFile(dir + "/late.txt").find("--start-utime = 9223372036854775807: must be in [0, "),
            std::string::npos) << ReadFile(dir + "/late.txt");
  // The log must not overwrite its scenario.
  EXPECT_EQ(SimLog({"--scenario", dir + "/bad.yaml", "--out", dir + "/bad.yaml"}, dir + "/self.txt"), 2);
  EXPECT_NE(ReadFile(dir + "/self.txt").find("is also the input --scenario"), std::string::npos)
      << ReadFile(dir + "/self.txt");
  // ... nor the file a scenario's name resolves to.
  std::filesystem::create_directories(dir + "/scenarios");
  std::ofstream(dir + "/scenarios/mine.yaml") << "extends: paper_fig4_turn\n";
  const std::string yaml = ReadFile(dir + "/scenarios/mine.yaml");
  EXPECT_EQ(RunCommand({"env", "VTRACK_SCENARIO_DIR=" + dir + "/scenarios", BinDir() + "/vtrack-sim-log",
                        "--scenario", "mine", "--out", dir + "/scenarios/mine.yaml"},
                       dir + "/named.txt"), 2) << ReadFile(dir + "/named.txt");
  EXPECT_NE(ReadFile(dir + "/named.txt").find("is also the input --scenario"), std::string::npos)
      << ReadFile(dir + "/named.txt");
  EXPECT_EQ(ReadFile(dir + "/scenarios/mine.yaml"), yaml);
  EXPECT_EQ(SimLog({"--scenario", "urban_intersection", "--describe"}, dir + "/describe.txt"), 0);
  EXPECT_NE(ReadFile(dir + "/describe.txt").find("no overlapping footprints"), std::string::npos);
}

}  // namespace
}  // namespace vtrack
