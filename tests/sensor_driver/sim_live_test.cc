// The two live processes and lcm-logger on a real LCM bus (udpm://, inside a private network
// namespace: ctest runs this through scripts/vtrack-netns): a 10 s run gives a log with scans and
// poses at their rates and no gaps, whose messages are byte for byte those vtrack-sim-log writes
// for the same --start-utime; and processes started separately, with no shared option, agree on
// time through the wall clock.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/process.h"
#include "sensor_driver/sim/scenario.h"
#include "sensor_driver/sim/simulator.h"
#include "tests/support/lcm_log.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/object_list_t.hpp"
#include "vtrack/pose_t.hpp"

namespace vtrack {
namespace {

using namespace std::chrono_literals;
using testing::BinDir;
using testing::kTestBusUrl;
using testing::LoggedEvent;
using testing::ReadFile;
using testing::ReadLogEvents;
using testing::RecordDriverAndEgoPose;
using testing::RunCommand;
using testing::ScratchDir;
using testing::StopLogger;
using testing::Subprocess;

constexpr char kLoggerUrl[] = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";

template <class T>
T DecodeOrDie(const std::string& data) {
  T m;
  EXPECT_EQ(lcm_util::Decode(data.data(), data.size(), &m), lcm_util::DecodeError::kNone);
  return m;
}

std::map<std::string, std::vector<std::string>> ByChannel(const std::vector<LoggedEvent>& events) {
  std::map<std::string, std::vector<std::string>> out;
  for (const LoggedEvent& e : events) out[e.channel].push_back(e.data);
  return out;
}

TEST(SimLiveTest, TenSecondsOfDriverEgoPoseAndLogger) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = ScratchDir("sim_live");
  const std::string log = dir + "/live.lcm";
  const std::string scenario = "paper_fig4_turn";
  // One run of 10 s starting on a whole millisecond 2.5 s from now (the processes wait for it).
  const std::int64_t start = (lcm_util::WallUtime() / 1000 + 2500) * 1000;
  const std::vector<std::string> common{"--scenario", scenario, "--duration", "10",
                                        "--start-utime", std::to_string(start), "--laps", "1",
                                        "--lcm-url", kTestBusUrl};
  RecordDriverAndEgoPose(dir, common, kLoggerUrl, log, 30000ms, 500ms);
  ASSERT_FALSE(HasFatalFailure());
  const auto events = ReadLogEvents(log);
  sim::Simulator sim(sim::LoadScenario(sim::ResolveScenarioPath(scenario), 10.0));
  std::vector<ladar_scan_t> scans;
  std::vector<object_list_t> truths;
  std::vector<pose_t> poses;
  for (const LoggedEvent& ev : events) {
    if (ev.channel == "LADAR_SCAN") {
      scans.push_back(DecodeOrDie<ladar_scan_t>(ev.data));
      // Received when the sweep was complete, within scheduling and network jitter.
      EXPECT_NEAR(static_cast<double>(ev.timestamp - scans.back().utime - scans.back().sweep_duration_us),
                  0.0, 200000.0);
    } else if (ev.channel == "GROUND_TRUTH") {
      truths.push_back(DecodeOrDie<object_list_t>(ev.data));
    } else if (ev.channel == "EGO_POSE") {
      poses.push_back(DecodeOrDie<pose_t>(ev.data));
      EXPECT_NEAR(static_cast<double>(ev.timestamp - poses.back().utime), 0.0, 200000.0);
    }
  }
  // At their rates, every one of them, none missing: 25 Hz scans, 100 Hz poses.
  ASSERT_EQ(static_cast<int>(scans.size()), sim.NumScans()) << ReadFile(dir + "/driver.txt");
  ASSERT_EQ(static_cast<int>(poses.size()), sim.NumPoses()) << ReadFile(dir + "/ego.txt");
  ASSERT_EQ(truths.size(), scans.size());
  EXPECT_EQ(sim.NumPoses(), 1000);
  EXPECT_GE(sim.NumScans(), 249);
  for (std::size_t i = 0; i < scans.size(); ++i) {
    EXPECT_EQ(scans[i].seq, static_cast<std::int64_t>(i));
    EXPECT_EQ(scans[i].utime, start + static_cast<std::int64_t>(i) * 40000);
    EXPECT_EQ(truths[i].utime, scans[i].utime);
  }
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_EQ(poses[k].utime, start + static_cast<std::int64_t>(k) * 10000);
  }

  // The same run written by vtrack-sim-log: the same messages, byte for byte, in the same order.
  const std::string ref = dir + "/ref.lcm";
  ASSERT_EQ(RunCommand({BinDir() + "/vtrack-sim-log", "--scenario", scenario, "--duration", "10",
                        "--start-utime", std::to_string(start), "--out", ref, "-q"},
                       dir + "/sim_log.txt"),
            0);
  const auto live = ByChannel(events), offline = ByChannel(ReadLogEvents(ref));
  for (const char* ch : {"LADAR_SCAN", "GROUND_TRUTH", "EGO_POSE"}) {
    ASSERT_EQ(live.at(ch).size(), offline.at(ch).size()) << ch;
    for (std::size_t i = 0; i < live.at(ch).size(); ++i) {
      ASSERT_TRUE(live.at(ch)[i] == offline.at(ch)[i]) << ch << " message " << i << " differs";
    }
  }
}

// --rate 0.5 (slow motion, for a consumer slower than real time): the messages are byte for byte
// those of vtrack-sim-log for the same --start-utime, only published at half the pace: the
// message for data time U + t arrives at wall time U + t / 0.5.
TEST(SimLiveTest, SlowMotionKeepsTheDataAndHalvesThePace) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = ScratchDir("sim_live_rate");
  const std::string log = dir + "/live.lcm";
  const std::string scenario = "paper_fig4_turn";
  const double rate = 0.5;
  const std::int64_t start = (lcm_util::WallUtime() / 1000 + 2500) * 1000;
  const std::vector<std::string> common{"--scenario", scenario, "--duration", "3", "--start-utime",
                                        std::to_string(start), "--laps", "1", "--rate", "0.5",
                                        "--lcm-url", kTestBusUrl, "-q"};
  RecordDriverAndEgoPose(dir, common, kLoggerUrl, log, 30000ms, 500ms);
  ASSERT_FALSE(HasFatalFailure());
  const std::string ref = dir + "/ref.lcm";
  ASSERT_EQ(RunCommand({BinDir() + "/vtrack-sim-log", "--scenario", scenario, "--duration", "3",
                        "--start-utime", std::to_string(start), "--out", ref, "-q"},
                       dir + "/sim_log.txt"),
            0);
  const auto events = ReadLogEvents(log);
  const auto live = ByChannel(events), offline = ByChannel(ReadLogEvents(ref));
  for (const char* ch : {"LADAR_SCAN", "GROUND_TRUTH", "EGO_POSE"}) {
    ASSERT_TRUE(live.count(ch)) << ch << " missing";
    ASSERT_EQ(live.at(ch).size(), offline.at(ch).size()) << ch;
    for (std::size_t i = 0; i < live.at(ch).size(); ++i) {
      ASSERT_TRUE(live.at(ch)[i] == offline.at(ch)[i]) << ch << " message " << i << " differs";
    }
  }
  // The pace: arrival (logger's wall clock) against the stamp, stretched by 1 / rate from U.
  int checked = 0;
  for (const LoggedEvent& ev : events) {
    std::int64_t due = 0;
    if (ev.channel == "LADAR_SCAN") {
      const auto scan = DecodeOrDie<ladar_scan_t>(ev.data);
      due = scan.utime + scan.sweep_duration_us;
    } else if (ev.channel == "EGO_POSE") {
      due = DecodeOrDie<pose_t>(ev.data).utime;
    } else {
      continue;
    }
    const double expected = static_cast<double>(start) + static_cast<double>(due - start) / rate;
    EXPECT_NEAR(static_cast<double>(ev.timestamp), expected, 200000.0) << ev.channel;
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

// A rate the schedule cannot honour is refused with a message naming it, before anything is sent.
TEST(SimLiveTest, BadRateIsRefused) {
  const std::string dir = ScratchDir("sim_live_bad_rate");
  for (const std::string bin : {"vtrack-ladar-driver", "vtrack-ego-pose"}) {
    EXPECT_NE(RunCommand({BinDir() + "/" + bin, "--scenario", "paper_fig4_turn", "--rate", "0.5",
                          "--lcm-url", "memq://"},
                         dir + "/no_start.txt"),
              0);
    EXPECT_NE(ReadFile(dir + "/no_start.txt").find("--start-utime"), std::string::npos)
        << ReadFile(dir + "/no_start.txt");
    EXPECT_NE(RunCommand({BinDir() + "/" + bin, "--scenario", "paper_fig4_turn", "--rate", "0",
                          "--start-utime", "1", "--lcm-url", "memq://"},
                         dir + "/zero.txt"),
              0);
    EXPECT_NE(ReadFile(dir + "/zero.txt").find("--rate"), std::string::npos)
        << ReadFile(dir + "/zero.txt");
  }
}

// --stop-after inf would publish nothing and exit 0, nan would never stop; NaN / negative model
// numbers, stray arguments and empty channel names would be taken silently: all refused with
// exit 2 and the option named, before anything is sent.
TEST(SimLiveTest, NonFiniteNumbersStrayArgumentsAndEmptyChannelsAreRefused) {
  const std::string dir = ScratchDir("sim_live_bad_options");
  const std::string out = dir + "/out.txt";
  for (const std::string bin : {"vtrack-ladar-driver", "vtrack-ego-pose"}) {
    const std::vector<std::string> base = {BinDir() + "/" + bin, "--scenario", "paper_fig4_turn",
                                           "--lcm-url", "memq://"};
    auto run = [&](std::vector<std::string> extra, const std::string& said) {
      std::vector<std::string> argv = base;
      argv.insert(argv.end(), extra.begin(), extra.end());
      EXPECT_EQ(RunCommand(argv, out, std::chrono::seconds(30)), 2) << bin << " " << extra.front();
      EXPECT_NE(ReadFile(out).find(said), std::string::npos) << ReadFile(out);
    };
    for (const char* v : {"inf", "nan", "-1"}) run({"--stop-after", v}, "--stop-after");
    run({"--rate", "inf", "--start-utime", "1"}, "--rate");
    run({"--duration", "nan"}, "--duration");
    run({"stray"}, "unexpected argument 'stray'");
  }
  auto refused = [&](const std::string& bin, std::vector<std::string> argv, const std::string& said) {
    argv.insert(argv.begin(), BinDir() + "/" + bin);
    EXPECT_EQ(RunCommand(argv, out, std::chrono::seconds(30)), 2) << bin << " " << argv.back();
    EXPECT_NE(ReadFile(out).find(said), std::string::npos) << ReadFile(out);
  };
  const std::vector<std::string> scene = {"--scenario", "paper_fig4_turn", "--lcm-url", "memq://"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = scene;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  refused("vtrack-ladar-driver", with({"--dropout", "nan"}), "--dropout");
  refused("vtrack-ladar-driver", with({"--range-noise", "-0.1"}), "--range-noise");
  refused("vtrack-ladar-driver", with({"--scan-channel", ""}), "--scan-channel must not be empty");
  refused("vtrack-ladar-driver", with({"--truth-channel", ""}), "--truth-channel must not be empty");
  refused("vtrack-ego-pose", with({"--channel", ""}), "--channel must not be empty");
  refused("vtrack-ego-pose", with({"--pose-rate", "nan"}), "--pose-rate");
  // The log writer shares the channel and number checks.
  const std::vector<std::string> to_log = {"--scenario", "paper_fig4_turn", "--out", dir + "/never.lcm"};
  auto log_with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = to_log;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  refused("vtrack-sim-log", log_with({"--pose-channel", ""}), "--pose-channel must not be empty");
  refused("vtrack-sim-log", log_with({"--duration", "inf"}), "--duration");
  refused("vtrack-sim-log", log_with({"stray"}), "unexpected argument 'stray'");
}

// No --start-utime: the ego-pose process and the driver, started 1.3 s apart, each join the lap in
// progress on the wall-clock grid. Every scan's and every pose's content equals vtrack-sim-log's
// for that lap (seq aside: live it counts on across laps).
TEST(SimLiveTest, SeparatelyStartedProcessesAgreeOnTheWallClock) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = ScratchDir("sim_live_grid");
  const std::string log = dir + "/live.lcm";
  const std::string scenario = "paper_fig4_turn";
  {
    Subprocess logger({"lcm-logger", "-q", "-f", std::string("--lcm-url=") + kLoggerUrl, log},
                      dir + "/logger.txt");
    std::this_thread::sleep_for(300ms);
    Subprocess ego({BinDir() + "/vtrack-ego-pose", "--scenario", scenario, "--stop-after", "5",
                    "--lcm-url", kTestBusUrl},
                   dir + "/ego.txt");
    std::this_thread::sleep_for(1300ms);
    Subprocess driver({BinDir() + "/vtrack-ladar-driver", "--scenario", scenario, "--stop-after",
                       "3", "--lcm-url", kTestBusUrl},
                      dir + "/driver.txt");
    const auto d_st = driver.Wait(15000ms), e_st = ego.Wait(15000ms);
    ASSERT_TRUE(d_st.has_value() && e_st.has_value());
    EXPECT_EQ(*d_st, 0) << ReadFile(dir + "/driver.txt");
    EXPECT_EQ(*e_st, 0) << ReadFile(dir + "/ego.txt");
    StopLogger(&logger, 500ms);
  }
  const std::int64_t lap = 16'000'000;  // the scenario's duration: laps start at multiples of it
  std::map<std::int64_t, std::map<std::string, std::map<std::int64_t, std::string>>> ref;  // lap -> channel -> utime -> bytes
  auto reference = [&](std::int64_t lap_start) -> auto& {
    if (!ref.count(lap_start)) {
      const std::string path = dir + "/ref_" + std::to_string(lap_start) + ".lcm";
      EXPECT_EQ(RunCommand({BinDir() + "/vtrack-sim-log", "--scenario", scenario, "--start-utime",
                            std::to_string(lap_start), "--out", path, "-q"}),
                0);
      for (const LoggedEvent& e : ReadLogEvents(path)) {
        std::int64_t utime;
        if (e.channel == "EGO_POSE") utime = DecodeOrDie<pose_t>(e.data).utime;
        else if (e.channel == "LADAR_SCAN") utime = DecodeOrDie<ladar_scan_t>(e.data).utime;
        else utime = DecodeOrDie<object_list_t>(e.data).utime;
        ref[lap_start][e.channel][utime] = e.data;
      }
    }
    return ref[lap_start];
  };
  int scans = 0, poses = 0;
  for (const LoggedEvent& e : ReadLogEvents(log)) {
    if (e.channel == "EGO_POSE") {
      const pose_t p = DecodeOrDie<pose_t>(e.data);
      auto& r = reference(p.utime / lap * lap)["EGO_POSE"];
      ASSERT_TRUE(r.count(p.utime)) << "pose at utime " << p.utime << " is off the grid";
      EXPECT_TRUE(r.at(p.utime) == e.data) << "pose at utime " << p.utime << " differs";
      ++poses;
    } else if (e.channel == "LADAR_SCAN") {
      ladar_scan_t s = DecodeOrDie<ladar_scan_t>(e.data);
      auto& r = reference(s.utime / lap * lap)["LADAR_SCAN"];
      ASSERT_TRUE(r.count(s.utime)) << "scan at utime " << s.utime << " is off the grid";
      ladar_scan_t expected = DecodeOrDie<ladar_scan_t>(r.at(s.utime));
      EXPECT_EQ(s.seq % 400, expected.seq);  // 400 scans per lap; seq counts on across laps
      s.seq = expected.seq;
      std::string a(s.getEncodedSize(), '\0'), b(expected.getEncodedSize(), '\0');
      s.encode(a.data(), 0, static_cast<int>(a.size()));
      expected.encode(b.data(), 0, static_cast<int>(b.size()));
      EXPECT_TRUE(a == b) << "scan at utime " << s.utime << " differs";
      ++scans;
    }
  }
  EXPECT_GE(poses, 400);  // 5 s at 100 Hz
  EXPECT_GE(scans, 60);   // 3 s at 25 Hz
}

}  // namespace
}  // namespace vtrack
