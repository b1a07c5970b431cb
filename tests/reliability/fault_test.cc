// Faults on a real LCM bus, inside the private network namespace (ctest runs this through
// scripts/vtrack-netns; nftables rules made here live and die with that namespace):
//  - datagram loss: an nftables rule drops 1% / 5% of the UDP datagrams that the sensor processes
//    (vtrack-ladar-driver, vtrack-ego-pose, run as uid 65534 so the rule can pick them out by
//    their socket's owner) send on the LCM port, while the tracker's own output goes through
//    unharmed and is recorded whole. The tracker keeps running and keeps its tracks (scored
//    with vtrack-eval against the same lap's truth written by vtrack-sim-log, and compared with
//    a clean run alongside), and TRACKER_STATUS counts the lost scans (scan_seq_gap);
//  - a renderer stopped with SIGSTOP for 5 s does not delay TRACKS;
//  - lcm-logger records every 2 MB scan at 10 Hz while the tracker runs on them.
// The runs of one test share the namespace on different UDP ports and run side by side.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "lcmtypes/util/process.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "lcmtypes/util/ladar_slices.h"
#include "vtrack/ladar_scan_t.hpp"
#include "vtrack/ladar_slice_t.hpp"
#include "vtrack/track_list_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack::testing {
namespace {

using namespace std::chrono_literals;

constexpr char kNobody[] = "65534";  // uid/gid of the sensor processes (nftables picks them out)

std::string Bin(const std::string& name) { return BinDir() + "/" + name; }
std::string Url(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=8388608";
}

// The sensor processes run unprivileged (setpriv), so that an nftables rule on the socket owner
// drops only what they send.
std::vector<std::string> AsNobody(std::vector<std::string> argv) {
  argv.insert(argv.begin(), {"setpriv", std::string("--reuid=") + kNobody,
                             std::string("--regid=") + kNobody, "--clear-groups", "--"});
  return argv;
}

// Skips unless nftables works here and setpriv can drop to uid 65534 (root in the namespace).
#define REQUIRE_FAULT_TOOLS(dir)                                                                \
  do {                                                                                          \
    VTRACK_REQUIRE_PRIVATE_NETNS();                                                             \
    if (RunCommand({"nft", "list", "ruleset"}, (dir) + "/nft_probe.txt") != 0) {                \
      GTEST_SKIP() << "nft (Debian package nftables) is not usable here: "                     \
                   << ReadFile((dir) + "/nft_probe.txt");                                       \
    }                                                                                           \
    if (RunCommand(AsNobody({"true"}), (dir) + "/setpriv_probe.txt") != 0) {                    \
      GTEST_SKIP() << "cannot run a process as uid 65534 (not root?): "                        \
                   << ReadFile((dir) + "/setpriv_probe.txt");                                   \
    }                                                                                           \
  } while (0)

// nftables: drop percent% of the datagrams that uid 65534 sends to port, at random.
void DropDatagrams(const std::string& dir, int port, int percent) {
  const std::string table = "vtrack_fault_" + std::to_string(port);
  std::ofstream f(dir + "/" + table + ".nft");
  f << "table inet " << table << " {\n"
    << "  chain out {\n"
    << "    type filter hook output priority 0; policy accept;\n"
    << "    meta skuid " << kNobody << " udp dport " << port << " numgen random mod 100 < " << percent
    << " counter drop\n"
    << "  }\n"
    << "}\n";
  f.close();
  ASSERT_EQ(RunCommand({"nft", "-f", dir + "/" + table + ".nft"}, dir + "/nft_" + table + ".txt"), 0)
      << ReadFile(dir + "/nft_" + table + ".txt");
}

// The number of datagrams the rule on port dropped (its counter).
long DroppedByRule(const std::string& dir, int port) {
  const std::string table = "vtrack_fault_" + std::to_string(port);
  RunCommand({"nft", "list", "table", "inet", table}, dir + "/count_" + table + ".txt");
  std::smatch m;
  const std::string s = ReadFile(dir + "/count_" + table + ".txt");
  return std::regex_search(s, m, std::regex("packets ([0-9]+)")) ? std::stol(m[1]) : -1;
}

// Driver + ego pose (as uid 65534) + tracker + lcm-logger of the tracker's output, on one port,
// for one lap of `duration` s of the scenario starting at start_utime. Started and stopped by
// the caller so that several pipelines run side by side.
struct Pipeline {
  Pipeline(const std::string& dir, const std::string& scenario, int port, std::int64_t start_utime,
           double duration, const std::string& log_channels, bool sensors_as_nobody,
           const std::vector<std::string>& driver_args = {}, double rate = 1.0)
      : log(dir + "/out_" + std::to_string(port) + ".lcm"),
        logger({"lcm-logger", "-q", "-f", "-c", log_channels, "--lcm-url=" + Url(port), log},
               dir + "/logger_" + std::to_string(port) + ".txt"),
        tracker({Bin("vtrack-tracker"), "--lcm-url", Url(port)}, dir + "/tracker_" + std::to_string(port) + ".txt") {
    std::this_thread::sleep_for(300ms);
    const std::string u = std::to_string(start_utime), d = std::to_string(duration), r = std::to_string(rate);
    auto as = [&](std::vector<std::string> argv) { return sensors_as_nobody ? AsNobody(std::move(argv)) : argv; };
    ego = std::make_unique<Subprocess>(
        as({Bin("vtrack-ego-pose"), "--scenario", scenario, "--start-utime", u, "--duration", d,
                  "--laps", "1", "--rate", r, "-q", "--lcm-url", Url(port)}),
        dir + "/ego_" + std::to_string(port) + ".txt");
    std::vector<std::string> driver_argv = {Bin("vtrack-ladar-driver"), "--scenario", scenario,
                                            "--start-utime", u, "--duration", d, "--laps", "1", "--rate", r,
                                            "-q", "--lcm-url", Url(port)};
    driver_argv.insert(driver_argv.end(), driver_args.begin(), driver_args.end());
    driver = std::make_unique<Subprocess>(
        as(driver_argv),
        dir + "/driver_" + std::to_string(port) + ".txt");
    tracker_log = dir + "/tracker_" + std::to_string(port) + ".txt";
  }
  // Waits for the sensor processes to finish their lap, then stops tracker and logger.
  void Finish(std::chrono::milliseconds limit) {
    const auto rd = driver->Wait(limit);
    const auto re = ego->Wait(5s);
    EXPECT_TRUE(rd && *rd == 0) << "driver: " << (rd ? *rd : -1);
    EXPECT_TRUE(re && *re == 0) << "ego pose: " << (re ? *re : -1);
    std::this_thread::sleep_for(1500ms);  // the last scans processed, a TRACKER_STATUS out
    tracker_rc = tracker.Stop();
    std::this_thread::sleep_for(300ms);
    logger.Stop();
  }

  std::string log, tracker_log;
  Subprocess logger, tracker;
  std::unique_ptr<Subprocess> ego, driver;
  int tracker_rc = -1;
};

tracker_status_t LastStatus(const std::string& path) {
  tracker_status_t last;
  lcm_util::LogReader r(path);
  while (const lcm::LogEvent* ev = r.Next()) {
    if (ev->channel == "TRACKER_STATUS") lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &last);
  }
  return last;
}

std::int64_t Reason(const tracker_status_t& s, const std::string& reason) {
  for (int i = 0; i < s.num_reasons; ++i) {
    if (s.reject_reason[i] == reason) return s.reject_count[i];
  }
  return 0;
}

// One number from vtrack-eval's JSON summary.
double JsonNumber(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\": *(-?[0-9.eE+-]+)"))) return NAN;
  return std::stod(m[1]);
}

struct Score {
  double mota = NAN, mota_coasting = NAN;
  int id_switches = -1, id_switches_coasting = -1;
  int tracks_on_truth = -1;  // scored tracks (coasting ones too) matched to a truth object at least once
};

// vtrack-eval of the recorded TRACKS against the lossless truth of the same lap: confirmed
// tracks only (the default), and with coasting tracks scored too (a track that coasts over lost
// scans is still there for the planner).
Score Evaluate(const std::string& dir, const std::string& truth_log, const std::string& tracks_log) {
  Score s;
  const std::string j1 = tracks_log + ".json", j2 = tracks_log + ".coasting.json";
  EXPECT_EQ(RunCommand({Bin("vtrack-eval"), truth_log, tracks_log, "--json", j1, "-q"}, dir + "/eval.txt"), 0)
      << ReadFile(dir + "/eval.txt");
  const std::string csv = tracks_log + ".coasting.csv";
  EXPECT_EQ(RunCommand({Bin("vtrack-eval"), truth_log, tracks_log, "--json", j2, "--score-coasting",
                        "--csv", csv, "-q"},
                       dir + "/eval.txt"), 0)
      << ReadFile(dir + "/eval.txt");
  // The per-track CSV: track_id,first_s,last_s,scans,matched,...
  std::istringstream rows(ReadFile(csv));
  std::string row;
  std::getline(rows, row);  // header
  s.tracks_on_truth = 0;
  while (std::getline(rows, row)) {
    std::istringstream fields(row);
    std::string f;
    for (int k = 0; k < 5 && std::getline(fields, f, ','); ++k) {}
    if (!f.empty() && std::stol(f) > 0) ++s.tracks_on_truth;
  }
  const std::string a = ReadFile(j1), b = ReadFile(j2);
  s.mota = JsonNumber(a, "mota");
  s.mota_coasting = JsonNumber(b, "mota");
  s.id_switches = static_cast<int>(JsonNumber(a, "id_switches"));
  s.id_switches_coasting = static_cast<int>(JsonNumber(b, "id_switches"));
  return s;
}

struct LossRun {
  int percent = 0;
  int published = 0;             // scans in the lap
  double datagrams_per_scan = 0;
  std::string log, truth;        // the run's recording, the lossless lap (vtrack-sim-log)
  std::string tracker_log;       // the tracker's stderr
  long datagrams_dropped = 0;
  tracker_status_t status;
  Score score;
  int scored_tracks = 0;
};

// One pipeline per loss level, side by side on their own ports, for one lap of `duration` s.
// driver_args go to vtrack-ladar-driver and vtrack-sim-log (e.g. --slices 0); log_channels: what
// lcm-logger records besides the tracker's output.
std::vector<LossRun> RunLoss(const std::string& dir, const std::string& scenario, double duration,
                             const std::vector<int>& percent,
                             const std::vector<std::string>& driver_args = {},
                             const std::string& log_channels = "TRACKS|TRACKER_STATUS",
                             int first_port = 7711) {
  std::vector<int> port;
  for (std::size_t i = 0; i < percent.size(); ++i) port.push_back(first_port + static_cast<int>(i));
  for (std::size_t i = 0; i < percent.size(); ++i) {
    if (percent[i] > 0) DropDatagrams(dir, port[i], percent[i]);
  }
  if (::testing::Test::HasFatalFailure()) return {};
  const std::int64_t start = lcm_util::WallUtime() + 3'000'000;
  {
    std::vector<std::unique_ptr<Pipeline>> runs;
    for (int p : port) {
      runs.push_back(std::make_unique<Pipeline>(dir, scenario, p, start, duration, log_channels,
                                                true, driver_args));
    }
    for (auto& r : runs) r->Finish(std::chrono::milliseconds(static_cast<int>((duration + 30) * 1000)));
    for (auto& r : runs) EXPECT_EQ(r->tracker_rc, 0) << ReadFile(r->tracker_log);
  }
  const std::string truth = dir + "/truth.lcm";
  std::vector<std::string> sim = {Bin("vtrack-sim-log"), "--scenario", scenario, "--start-utime",
                                  std::to_string(start), "--duration", std::to_string(duration),
                                  "--out", truth, "-q"};
  sim.insert(sim.end(), driver_args.begin(), driver_args.end());
  EXPECT_EQ(RunCommand(sim, dir + "/sim.txt"), 0);
  int published = 0;
  double datagrams = 0;
  {
    // LCM sends a message of more than 65499 bytes as fragments of 65487 (lcm_udpm, Linux).
    lcm_util::LogReader r(truth);
    std::set<std::int64_t> sliced;  // seq of sweeps sent as slices
    while (const lcm::LogEvent* ev = r.Next()) {
      if (ev->channel == "LADAR_SLICE") {
        ladar_slice_t s;
        if (lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &s) == lcm_util::DecodeError::kNone &&
            sliced.insert(s.seq).second) {
          ++published;
        }
      } else if (ev->channel != "LADAR_SCAN") {
        continue;
      } else {
        ++published;
      }
      datagrams += ev->datalen <= 65499 ? 1 : std::ceil(ev->datalen / 65487.0);
    }
  }
  std::vector<LossRun> out;
  for (std::size_t i = 0; i < port.size(); ++i) {
    LossRun r;
    r.percent = percent[i];
    r.published = published;
    r.datagrams_per_scan = published ? datagrams / published : 0;
    r.truth = truth;
    r.datagrams_dropped = percent[i] ? DroppedByRule(dir, port[i]) : 0;
    const std::string log = dir + "/out_" + std::to_string(port[i]) + ".lcm";
    r.log = log;
    r.tracker_log = dir + "/tracker_" + std::to_string(port[i]) + ".txt";
    r.status = LastStatus(log);
    r.score = Evaluate(dir, truth, log);
    r.scored_tracks = static_cast<int>(JsonNumber(ReadFile(log + ".coasting.json"), "scored_tracks"));
    const std::int64_t gaps = Reason(r.status, "scan_seq_gap");
    const double p = percent[i] / 100.0;
    std::printf("%s, loss %d%% of datagrams (%.1f per scan: a whole scan arrives with P = %.3f): %ld datagrams "
                "dropped; scans published %d, received %lld, counted lost (scan_seq_gap) %lld, processed "
                "%lld; MOTA %.3f (coasting tracks scored: %.3f), id switches %d (%d), tracks scored %d (on a truth object %d)\n",
                scenario.c_str(), percent[i], r.datagrams_per_scan, std::pow(1 - p, r.datagrams_per_scan),
                r.datagrams_dropped, published, static_cast<long long>(r.status.scans_received),
                static_cast<long long>(gaps), static_cast<long long>(r.status.scans_processed), r.score.mota,
                r.score.mota_coasting, r.score.id_switches, r.score.id_switches_coasting, r.scored_tracks, r.score.tracks_on_truth);
    // Kept running to the end, and the loss is counted: received + counted gaps = published, up
    // to scans lost before the first or after the last received one (no gap to see).
    EXPECT_GT(r.status.scans_received, 0);
    EXPECT_LE(r.status.scans_received + gaps, published);
    EXPECT_GE(r.status.scans_received + gaps, published - 3);
    if (percent[i] == 0) {
      EXPECT_EQ(gaps, 0);
    }
    out.push_back(r);
  }
  return out;
}

TEST(FaultTest, DatagramLossTrackerCoastsKeepsItsTracksAndCountsTheLoss) {
  const std::string dir = ScratchDir("fault_loss");
  REQUIRE_FAULT_TOOLS(dir);
  const std::vector<LossRun> runs = RunLoss(dir, "paper_fig4_turn", 14.0, {0, 1, 5});
  ASSERT_EQ(runs.size(), 3u);
  for (const LossRun& r : runs) {
    // Every scan that arrived was processed, unless the lost datagrams were the poses around it
    // (the pose stream is one datagram per pose): then it is refused, counted by that reason.
    const std::int64_t no_pose = Reason(r.status, "pose_missing") + Reason(r.status, "stale_pose");
    std::printf("  %d%%: scans dropped %lld, for want of a pose %lld\n", r.percent,
                static_cast<long long>(r.status.scans_dropped), static_cast<long long>(no_pose));
    EXPECT_EQ(r.status.scans_dropped, no_pose);
    EXPECT_LE(r.status.scans_dropped, r.percent == 0 ? 0 : 2);
    EXPECT_EQ(r.status.scans_processed + r.status.scans_dropped, r.status.scans_received);
    if (r.percent > 0) {
      // Single-plane scans are one datagram each, lost with probability p: binomial bounds
      // (mean +- 5 sigma, + 2 for scans lost at the ends).
      const double n = r.published, p = r.percent / 100.0;
      const double mean = n * p, sigma = std::sqrt(n * p * (1 - p));
      const auto gaps = static_cast<double>(Reason(r.status, "scan_seq_gap"));
      EXPECT_GE(gaps, std::floor(mean - 5 * sigma) - 2);
      EXPECT_LE(gaps, std::ceil(mean + 5 * sigma) + 2);
    }
  }
  // The tracks are kept through the loss: (nearly) the clean run's MOTA with coasting tracks
  // scored, no identity switch and no track re-created beyond the clean run's (a track on a truth
  // object; a short-lived false positive, e.g. a piece of clutter classed vehicle for 0.3 s in one
  // 5% run, is counted by the MOTA bound instead).
  EXPECT_GT(runs[0].score.mota_coasting, 0.0);
  EXPECT_GE(runs[1].score.mota_coasting, runs[0].score.mota_coasting - 0.05);
  EXPECT_GE(runs[2].score.mota_coasting, runs[0].score.mota_coasting - 0.10);
  for (int i : {1, 2}) {
    EXPECT_LE(runs[i].score.id_switches_coasting, runs[0].score.id_switches_coasting);
    EXPECT_LE(runs[i].score.tracks_on_truth, runs[0].score.tracks_on_truth);
  }
}

// The same with 64-layer scans sent whole (--slices 0: ~2.8 MB, 44 datagrams each): a measurement for
// docs/reliability.md, too heavy for CI (three 64-layer pipelines side by side). Run with
//   scripts/vtrack-netns build/tests/reliability_fault_test --gtest_also_run_disabled_tests
//       --gtest_filter='*64Layer*'    (one line)
TEST(FaultTest, DISABLED_DatagramLoss64LayerScans) {
  const std::string dir = ScratchDir("fault_loss64");
  REQUIRE_FAULT_TOOLS(dir);
  const std::vector<LossRun> runs =
      RunLoss(dir, "urban_intersection", 20.0, {0, 1, 5}, {"--slices", "0"});
  ASSERT_EQ(runs.size(), 3u);
  for (const LossRun& r : runs) {
    // Scans arrive whole or not at all: the expected count is (1 - p)^fragments of them.
    const double p_arrive = std::pow(1 - r.percent / 100.0, r.datagrams_per_scan);
    const double n = r.published, mean = n * p_arrive, sigma = std::sqrt(n * p_arrive * (1 - p_arrive));
    EXPECT_GE(r.status.scans_received, std::floor(mean - 5 * sigma) - 1);
    EXPECT_LE(r.status.scans_received, std::ceil(mean + 5 * sigma) + 1);
  }
}

// Slices and returns: published (counted in the lossless lap written by vtrack-sim-log), or
// received and processed by the tracker (its last words on stderr).
struct SliceCounts {
  std::int64_t slices = 0, returns = 0, returns_processed = 0;
};

SliceCounts Published(const std::string& log) {
  SliceCounts c;
  lcm_util::LogReader r(log);
  while (const lcm::LogEvent* ev = r.Next()) {
    if (ev->channel != "LADAR_SLICE") continue;
    ladar_slice_t s;
    if (lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &s) != lcm_util::DecodeError::kNone) continue;
    ++c.slices;
    c.returns += s.npoints;
  }
  c.returns_processed = c.returns;
  return c;
}

SliceCounts ReceivedByTracker(const std::string& tracker_stderr) {
  SliceCounts c;
  std::smatch m;
  const std::string s = ReadFile(tracker_stderr);
  if (std::regex_search(s, m, std::regex("([0-9]+) slices received; ([0-9]+) returns received, ([0-9]+) processed"))) {
    c.slices = std::stoll(m[1]);
    c.returns = std::stoll(m[2]);
    c.returns_processed = std::stoll(m[3]);
  } else {
    ADD_FAILURE() << "no counts in the tracker's output: " << s;
  }
  return c;
}

// 64-layer sweeps sent as slices of one datagram each (the driver's default): a measurement for
// docs/reliability.md ("Datagram loss, 64-layer sweeps"), too heavy for CI (three 64-layer
// pipelines and their recordings side by side). Run with
//   scripts/vtrack-netns build/tests/reliability_fault_test --gtest_also_run_disabled_tests
//       --gtest_filter='*SlicedSweeps*'    (one line)
TEST(FaultTest, DISABLED_DatagramLoss64LayerSlicedSweeps) {
  const std::string dir = ScratchDir("fault_loss64_sliced");
  REQUIRE_FAULT_TOOLS(dir);
  // Side by side on one start time: the lap's tracks depend on its absolute time (vtrack-eval's
  // MOTA of the same 20 s at start times 100 s apart: 0.653 and 0.623), so only runs of the same
  // lap compare.
  const std::vector<LossRun> runs = RunLoss(dir, "urban_intersection", 20.0, {0, 1, 5}, {},
                                            "TRACKS|TRACKER_STATUS", 7721);
  ASSERT_EQ(runs.size(), 3u);
  const SliceCounts sent = Published(runs[0].truth);
  ASSERT_GT(sent.slices, 0) << "the lap was not sent as slices";
  std::vector<double> processed_share;
  for (const LossRun& r : runs) {
    const SliceCounts got = ReceivedByTracker(r.tracker_log);
    const double processed = static_cast<double>(got.returns_processed) / sent.returns;
    processed_share.push_back(processed);
    std::printf("sliced, loss %d%%: %ld datagrams dropped; slices published %lld, received %lld, "
                "counted lost by the tracker %lld (%lld deg); sweeps partial %lld of %lld processed; "
                "returns published %lld, received %lld (%.1f %%), processed %lld (%.1f %%); MOTA "
                "%.3f (lossless %.3f, difference %+.3f), id switches %d (lossless %d)\n",
                r.percent, r.datagrams_dropped, static_cast<long long>(sent.slices),
                static_cast<long long>(got.slices),
                static_cast<long long>(Reason(r.status, "slice_lost")),
                static_cast<long long>(Reason(r.status, "slice_lost_deg")),
                static_cast<long long>(Reason(r.status, "sweep_partial")),
                static_cast<long long>(r.status.scans_processed),
                static_cast<long long>(sent.returns), static_cast<long long>(got.returns),
                100.0 * static_cast<double>(got.returns) / sent.returns,
                static_cast<long long>(got.returns_processed), 100.0 * processed, r.score.mota,
                runs[0].score.mota, r.score.mota - runs[0].score.mota, r.score.id_switches,
                runs[0].score.id_switches);
    // A lost datagram costs the tracker one slice (or one pose), nothing more: no slice lost on
    // the receiving side (socket buffer, LCM's queue), none too late for its sweep.
    EXPECT_LE(Reason(r.status, "slice_lost"), r.datagrams_dropped);
    EXPECT_EQ(Reason(r.status, "slice_late"), 0);
  }
  // Lossless: every slice and return reached the tracker and was processed.
  EXPECT_DOUBLE_EQ(processed_share[0], 1.0);
  // The target at 5 %: at least 90 % of the returns processed, MOTA within 0.02 of lossless.
  EXPECT_GE(processed_share[2], 0.9);
  EXPECT_GE(runs[2].score.mota, runs[0].score.mota - 0.02);
}

// TRACKS delay after the sweep = logger receive time - the instant the scan was complete (utime + sweep).
struct Delays {
  std::vector<double> during, outside;  // [ms]
};

TEST(FaultTest, RendererStoppedFor5sNeverDelaysTracks) {
  const std::string dir = ScratchDir("fault_renderer");
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string scenario = "paper_fig4_turn";
  const double duration = 14.0;
  const int port = 7714;
  const std::int64_t start = lcm_util::WallUtime() + 3'000'000;
  const std::int64_t stop_at = start + 4'000'000, cont_at = stop_at + 5'000'000;
  int render_rc = -1;
  std::string render_out;
  {
    Subprocess render({Bin("vtrack-render"), "--lcm-url", Url(port), "--video", dir + "/live.mp4", "-q"},
                      dir + "/render.txt");
    Pipeline run(dir, scenario, port, start, duration, "TRACKS|TRACKER_STATUS", false);
    std::this_thread::sleep_for(std::chrono::microseconds(stop_at - lcm_util::WallUtime()));
    ASSERT_TRUE(render.Running()) << ReadFile(dir + "/render.txt");
    render.Signal(SIGSTOP);
    std::this_thread::sleep_for(std::chrono::microseconds(cont_at - lcm_util::WallUtime()));
    render.Signal(SIGCONT);
    run.Finish(std::chrono::milliseconds(static_cast<int>((duration + 30) * 1000)));
    EXPECT_EQ(run.tracker_rc, 0) << ReadFile(run.tracker_log);
    render.Signal(SIGINT);
    const auto rc = render.Wait(20s);
    render_rc = rc ? *rc : -1;
  }
  render_out = ReadFile(dir + "/render.txt");
  EXPECT_EQ(render_rc, 0) << render_out;  // the renderer survived being stopped and ended cleanly

  const std::string truth = dir + "/truth.lcm";
  ASSERT_EQ(RunCommand({Bin("vtrack-sim-log"), "--scenario", scenario, "--start-utime", std::to_string(start),
                        "--duration", std::to_string(duration), "--out", truth, "-q"}, dir + "/sim.txt"), 0);
  std::map<std::int64_t, std::int64_t> complete;  // scan utime -> utime + sweep
  {
    lcm_util::LogReader r(truth);
    while (const lcm::LogEvent* ev = r.Next()) {
      ladar_scan_t s;
      if (ev->channel == "LADAR_SCAN" && lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &s) == lcm_util::DecodeError::kNone) {
        complete[s.utime] = s.utime + s.sweep_duration_us;
      }
    }
  }
  Delays d;
  int during_scans = 0, during_tracks = 0;
  for (const auto& [u, c] : complete) during_scans += c >= stop_at && c < cont_at;
  {
    lcm_util::LogReader r(dir + "/out_" + std::to_string(port) + ".lcm");
    while (const lcm::LogEvent* ev = r.Next()) {
      track_list_t t;
      if (ev->channel != "TRACKS" || lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &t) != lcm_util::DecodeError::kNone) continue;
      const auto it = complete.find(t.utime);
      if (it == complete.end()) continue;
      const double ms = (ev->timestamp - it->second) * 1e-3;
      const bool during = it->second >= stop_at && it->second < cont_at;
      (during ? d.during : d.outside).push_back(ms);
      during_tracks += during;
    }
  }
  ASSERT_GT(d.during.size(), 10u);
  ASSERT_GT(d.outside.size(), 10u);
  std::sort(d.during.begin(), d.during.end());
  std::sort(d.outside.begin(), d.outside.end());
  auto q = [](const std::vector<double>& v, double f) { return v[static_cast<std::size_t>(f * (v.size() - 1))]; };
  std::printf("TRACKS delay after the sweep [ms]: renderer running: median %.1f, p90 %.1f, p99 %.1f, max %.1f (%zu scans); "
              "renderer stopped: median %.1f, p90 %.1f, p99 %.1f, max %.1f (%zu scans)\n",
              q(d.outside, 0.5), q(d.outside, 0.9), q(d.outside, 0.99), d.outside.back(), d.outside.size(),
              q(d.during, 0.5), q(d.during, 0.9), q(d.during, 0.99), d.during.back(), d.during.size());
  // Every scan of the stopped window answered, and no later than the scans around it
  // (allowance: 2x the running quantile + 20 ms of scheduling noise) up to its 90th percentile,
  // and none later than 100 ms. A publisher held up by the stopped renderer would delay the scans
  // of its 5 s by far more than 100 ms, and most of them. The window's p99 is its third latest
  // scan of 125, which on a shared machine wait for the CPU now and then (seen: one of 125 at
  // 29 ms against an allowance of 27, and 21.9 ms against 21.8, the median unchanged): that
  // measures the machine, not the publisher.
  EXPECT_EQ(during_tracks, during_scans);
  EXPECT_LE(q(d.during, 0.5), q(d.outside, 0.5) * 2 + 20);
  EXPECT_LE(q(d.during, 0.9), std::max(2 * q(d.outside, 0.9), q(d.outside, 0.9) + 20));
  EXPECT_LE(d.during.back(), 100.0);
}

// The driver's sweeps (urban_intersection: 64 layers, ~2.8 MB each, 10 Hz) as lcm-logger records
// them beside the tracker, against vtrack-sim-log's: every one, byte for byte. Whole sweeps
// (--slices 0, LADAR_SCAN), or slices (the default, LADAR_SLICE: keyed by sweep and index).
// In a sanitized build the sensors publish at LiveRate() (a fifth of real time): there the
// instrumented driver and tracker take both cores, and a logger starved of CPU for a few hundred
// ms overflows its socket buffer (net.core.rmem_max caps it: 4 MB here, a few sweeps), which
// measures the machine, not the logger. The 10 Hz claim is the Release tree's.
void LoggerRecordsEverySweep(bool sliced) {
  const std::string dir = ScratchDir(sliced ? "fault_logger_sliced" : "fault_logger");
  const std::string scenario = "urban_intersection";
  const std::string channel = sliced ? "LADAR_SLICE" : "LADAR_SCAN";
  const std::vector<std::string> args = sliced ? std::vector<std::string>{}
                                               : std::vector<std::string>{"--slices", "0"};
  const double duration = kSanitizedBuild ? 3.0 : 6.0;  // s of data; 15 s of wall time sanitized
  const int port = sliced ? 7716 : 7715;
  const std::int64_t start = lcm_util::WallUtime() + 3'000'000;
  {
    const double rate = LiveRate();
    Pipeline run(dir, scenario, port, start, duration, channel + "|TRACKS", false, args, rate);
    run.Finish(std::chrono::milliseconds(static_cast<int>((duration / rate + 60) * 1000)));
    EXPECT_EQ(run.tracker_rc, 0) << ReadFile(run.tracker_log);
  }
  const std::string truth = dir + "/truth.lcm";
  std::vector<std::string> sim = {Bin("vtrack-sim-log"), "--scenario", scenario, "--start-utime",
                                  std::to_string(start), "--duration", std::to_string(duration),
                                  "--out", truth, "-q"};
  sim.insert(sim.end(), args.begin(), args.end());
  ASSERT_EQ(RunCommand(sim, dir + "/sim.txt"), 0);
  // The logger's messages are the simulator's, every one, byte for byte; (seq, slice) -> bytes.
  using Key = std::pair<std::int64_t, int>;
  std::map<Key, std::string> want, got;
  std::map<std::int64_t, std::size_t> sweep_bytes;
  std::size_t largest = 0;
  auto read = [&](const std::string& path, std::map<Key, std::string>* out, bool count) {
    lcm_util::LogReader r(path);
    while (const lcm::LogEvent* ev = r.Next()) {
      if (ev->channel != channel) continue;
      const auto size = static_cast<std::size_t>(ev->datalen);
      Key key;
      if (sliced) {
        ladar_slice_t s;
        if (lcm_util::Decode(ev->data, size, &s) != lcm_util::DecodeError::kNone) continue;
        key = {s.seq, s.slice_index};
      } else {
        ladar_scan_t s;
        if (lcm_util::Decode(ev->data, size, &s) != lcm_util::DecodeError::kNone) continue;
        key = {s.seq, 0};
      }
      (*out)[key] = std::string(static_cast<const char*>(ev->data), size);
      if (count) {
        sweep_bytes[key.first] += size;
        largest = std::max(largest, size);
      }
    }
  };
  read(truth, &want, true);
  read(dir + "/out_" + std::to_string(port) + ".lcm", &got, false);
  std::size_t sweep_max = 0;
  for (const auto& [seq, bytes] : sweep_bytes) sweep_max = std::max(sweep_max, bytes);
  std::printf("logger (%s): %zu of %zu messages recorded, %zu sweeps, largest message %.3f MB, "
              "largest sweep %.2f MB\n", channel.c_str(), got.size(), want.size(), sweep_bytes.size(),
              largest / 1e6, sweep_max / 1e6);
  EXPECT_GE(sweep_bytes.size(), static_cast<std::size_t>(duration * 10) - 2);
  EXPECT_GT(sweep_max, 2'000'000u);
  if (sliced) {
    EXPECT_LE(largest, static_cast<std::size_t>(lcm_util::kMaxDatagramMessageBytes));
  }
  EXPECT_EQ(got.size(), want.size());
  int differ = 0;
  for (const auto& [key, bytes] : want) differ += !got.count(key) || got.at(key) != bytes;
  EXPECT_EQ(differ, 0);
  std::filesystem::remove(truth);
  std::filesystem::remove(dir + "/out_" + std::to_string(port) + ".lcm");
}

TEST(FaultTest, LoggerRecordsEvery2MBScanAt10HzWhileTheTrackerRuns) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  LoggerRecordsEverySweep(/*sliced=*/false);
}

TEST(FaultTest, LoggerRecordsEverySliceOf2MBSweepsAt10HzWhileTheTrackerRuns) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  LoggerRecordsEverySweep(/*sliced=*/true);
}

}  // namespace
}  // namespace vtrack::testing
