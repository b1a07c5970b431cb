// vtrack-tracker live on a real LCM bus (udpm://, inside a private network namespace: ctest runs
// this through scripts/vtrack-netns): the simulator's driver and ego-pose processes publish a
// scenario in real time, lcm-logger records everything, and the recording is scored against
// the ground truth on it. The same scenario written by vtrack-sim-log (byte for byte the same
// messages) is tracked offline, and the live TRACKS must match the offline ones; lcm-logplayer
// feeding the same log live must give the same too.
//
// ctest runs the cases whose names hold Urban or Kitti (64-beam sweeps in real time) alone, as
// tracker_live_test, and the others beside other tests, as tracker_live_single_plane_test
// (tests/integration/CMakeLists.txt): a new 64-beam case needs such a name.
#include <gtest/gtest.h>

#include <sched.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "lcmtypes/util/decode.h"
#include "lcmtypes/util/log_reader.h"
#include "lcmtypes/util/process.h"
#include "tests/integration/tracker_eval.h"
#include "tests/support/affinity.h"
#include "tests/support/subprocess.h"
#include "tests/support/test_env.h"
#include "vtrack/track_list_t.hpp"
#include "vtrack/tracker_status_t.hpp"

namespace vtrack::testing {
namespace {

using namespace std::chrono_literals;

const char* kLoggerUrl = "--lcm-url=udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";

std::string Bin(const std::string& name) { return BinDir() + "/" + name; }

// Compares two tracker outputs scan by scan: same track ids, states within tolerance [m, rad].
// Returns the number of scans compared; failures are reported.
int CompareTracks(const std::map<std::int64_t, track_list_t>& a,
                  const std::map<std::int64_t, track_list_t>& b, double tol) {
  int compared = 0, mismatched = 0;
  double worst = 0.0;
  for (const auto& [utime, la] : a) {
    const auto it = b.find(utime);
    if (it == b.end()) continue;
    ++compared;
    const track_list_t& lb = it->second;
    std::map<std::int64_t, const track_t*> ib;
    for (const auto& t : lb.tracks) ib[t.id] = &t;
    bool same = la.tracks.size() == lb.tracks.size();
    for (const auto& t : la.tracks) {
      const auto jt = ib.find(t.id);
      if (jt == ib.end()) {
        same = false;
        continue;
      }
      const double d = std::max({std::abs(t.x - jt->second->x), std::abs(t.y - jt->second->y),
                                 std::abs(t.theta - jt->second->theta)});
      worst = std::max(worst, d);
      if (d > tol) same = false;
    }
    if (!same && ++mismatched <= 3) {
      ADD_FAILURE() << "scan at " << utime << ": " << la.tracks.size() << " vs "
                    << lb.tracks.size() << " tracks, ids or states differ";
    }
  }
  std::printf("compared %d scans: %d differ, largest state difference %.3g\n", compared,
              mismatched, worst);
  return compared;
}

struct LiveRun {
  std::string dir, live_log, sim_log, offline;
  std::int64_t start_utime = 0;
  // With a kill: [us, wall clock] when the tracker was killed and when its successor started.
  std::int64_t killed_utime = 0, restarted_utime = 0;
  // The CPUs each thread of the live tracker may run on at the end of the lap, as the kernel
  // lists them (/proc/PID/task/TID/status, Cpus_allowed_list).
  std::vector<std::string> tracker_thread_cpus;
};

std::vector<std::string> ThreadCpus(pid_t pid) {
  std::vector<std::string> out;
  std::error_code error;  // the process gone: none
  for (const auto& task :
       std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/task", error)) {
    std::ifstream in(task.path() / "status");
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("Cpus_allowed_list:", 0) == 0) {
        out.push_back(line.substr(line.find_first_not_of(" \t", 18)));
      }
    }
  }
  return out;
}

// What happens to the live tracker during the lap, at_s seconds into it: killed (SIGKILL) and
// started again at once, both then taking their ids from their start time as in service; or
// stopped (SIGSTOP) for stop_s seconds, then continued.
struct TrackerFault {
  enum class Kind { kNone, kKill, kStop } kind = Kind::kNone;
  double at_s = 0.0;    // [s] into the lap
  double stop_s = 0.0;  // [s] kStop: how long
};

// Logger + tracker + driver + ego pose, one lap of the scenario; then the same lap offline.
// The lap is published at `rate` data seconds per wall second (the processes' --rate): the
// messages, and so the tracks, are the same at any pace; only how long the test waits changes.
LiveRun RunLive(const std::string& scenario, double duration_s, double rate = 1.0,
                TrackerFault fault = {}) {
  if (rate != 1.0) std::printf("publishing at %.3f x real time\n", rate);
  LiveRun run;
  run.dir = ScratchDir("tracker_live_" + scenario);
  run.live_log = run.dir + "/live.lcm";
  run.start_utime = lcm_util::WallUtime() + 3'000'000;  // processes up and subscribed by then
  const std::string u = std::to_string(run.start_utime);
  const std::string d = std::to_string(duration_s);
  const std::string r = std::to_string(rate);
  {
    Subprocess logger({"lcm-logger", "-q", "-f", kLoggerUrl, run.live_log}, run.dir + "/logger.txt");
    // Ids from 1, as offline (live, they start from the start time): compared one to one below.
    const bool kill = fault.kind == TrackerFault::Kind::kKill;
    std::vector<std::string> tracker_argv = {Bin("vtrack-tracker")};
    if (!kill) tracker_argv.insert(tracker_argv.end(), {"--first-track-id", "1"});
    auto tracker = std::make_unique<Subprocess>(tracker_argv, run.dir + "/tracker.txt");
    std::this_thread::sleep_for(500ms);
    Subprocess ego({Bin("vtrack-ego-pose"), "--scenario", scenario, "--start-utime", u,
                    "--duration", d, "--laps", "1", "--rate", r, "-q"},
                   run.dir + "/ego.txt");
    Subprocess driver({Bin("vtrack-ladar-driver"), "--scenario", scenario, "--start-utime", u,
                       "--duration", d, "--laps", "1", "--rate", r, "-q"},
                      run.dir + "/driver.txt");
    if (fault.kind != TrackerFault::Kind::kNone) {
      const std::int64_t at = run.start_utime + static_cast<std::int64_t>(fault.at_s / rate * 1e6);
      std::this_thread::sleep_for(std::chrono::microseconds(std::max<std::int64_t>(0, at - lcm_util::WallUtime())));
    }
    if (fault.kind == TrackerFault::Kind::kStop) {
      tracker->Signal(SIGSTOP);
      std::this_thread::sleep_for(std::chrono::microseconds(static_cast<std::int64_t>(fault.stop_s * 1e6)));
      tracker->Signal(SIGCONT);
    }
    if (kill) {
      run.killed_utime = lcm_util::WallUtime();
      tracker->Signal(SIGKILL);
      const auto rk = tracker->Wait(5s);
      EXPECT_TRUE(rk && *rk == 128 + SIGKILL);
      run.restarted_utime = lcm_util::WallUtime();
      tracker = std::make_unique<Subprocess>(tracker_argv, run.dir + "/tracker_restarted.txt");
    }
    const auto limit =
        std::chrono::milliseconds(static_cast<int>((3.0 + duration_s / rate + 30.0) * 1000));
    const auto rd = driver.Wait(limit);
    const auto re = ego.Wait(5s);
    EXPECT_TRUE(rd && *rd == 0) << ReadFile(run.dir + "/driver.txt");
    EXPECT_TRUE(re && *re == 0) << ReadFile(run.dir + "/ego.txt");
    std::this_thread::sleep_for(1s);
    run.tracker_thread_cpus = ThreadCpus(tracker->pid());
    EXPECT_EQ(tracker->Stop(), 0) << ReadFile(run.dir + (kill ? "/tracker_restarted.txt" : "/tracker.txt"));
    std::this_thread::sleep_for(300ms);
    logger.Stop();
  }
  // The same lap written straight to a log, and tracked offline.
  run.sim_log = run.dir + "/sim.lcm";
  EXPECT_EQ(RunCommand({Bin("vtrack-sim-log"), "--scenario", scenario, "--start-utime", u,
                        "--duration", d, "--out", run.sim_log, "-q"},
                       run.dir + "/sim.txt"),
            0);
  run.offline = run.dir + "/offline.lcm";
  EXPECT_EQ(RunCommand({Bin("vtrack-tracker"), "--input", run.sim_log, "--output", run.offline, "-q"},
                       run.dir + "/offline.txt"),
            0);
  return run;
}

tracker_status_t LastStatus(const std::string& path) {
  tracker_status_t last{};  // zeros if the log holds none
  lcm_util::LogReader r(path);
  while (const lcm::LogEvent* ev = r.Next()) {
    if (ev->channel == "TRACKER_STATUS") {
      lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &last);
    }
  }
  return last;
}

TEST(TrackerLiveTest, Fig4TurnLiveEveryVehicleTrackedNoIdentitySwitchSameAsOffline) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const LiveRun run = RunLive("paper_fig4_turn", 16.0);
  const EvalResult r = EvaluateTracks(run.live_log, run.live_log);
  std::printf("live paper_fig4_turn: %s\n", Summary(r).c_str());
  EXPECT_GT(r.due, 300);
  EXPECT_EQ(r.matched, r.due) << (r.misses.empty() ? "" : r.misses.front());
  EXPECT_EQ(r.id_switches, 0);
  const tracker_status_t st = LastStatus(run.live_log);
  EXPECT_EQ(st.scans_dropped, 0);
  EXPECT_GE(st.scans_processed, 390);
  // Fed live or from the log, the tracker gives the same ids and states (no message lost on the
  // loopback bus: the results are bit-identical; the tolerance allows for nothing else).
  EXPECT_GT(CompareTracks(TracksByUtime(run.live_log), TracksByUtime(run.offline), 1e-9), 390);
}

// kill -9 of the live tracker mid-lap, restarted at once: no id it gave before the kill appears
// after it (the successor's ids start from its start time), and the successor has confirmed
// vehicles again, as many as its predecessor last reported, within 1 s (message time) of its
// first TRACKS. Told apart by the logger's receive time of each TRACKS message.
TEST(TrackerLiveTest, KilledTrackerRestartsWithNewIdsAndItsTracksBackWithin1s) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const LiveRun run = RunLive("paper_fig4_turn", 16.0, 1.0, {TrackerFault::Kind::kKill, 8.0});
  ASSERT_GT(run.restarted_utime, run.killed_utime);
  std::set<std::int64_t> before_ids;
  int confirmed_before = 0, lists_before = 0, lists_after = 0;
  std::int64_t first_after_utime = 0;
  std::map<std::int64_t, int> confirmed_after;  // by message utime
  int reused = 0;
  lcm_util::LogReader reader(run.live_log);
  while (const lcm::LogEvent* ev = reader.Next()) {
    if (ev->channel != "TRACKS") continue;
    track_list_t m;
    ASSERT_EQ(lcm_util::Decode(ev->data, static_cast<std::size_t>(ev->datalen), &m),
              lcm_util::DecodeError::kNone);
    // Confirmed vehicles: what a consumer acts on (static clutter may take longer to confirm).
    int confirmed = 0;
    for (const track_t& t : m.tracks) {
      confirmed += t.status == track_t::STATUS_CONFIRMED && t.object_class == track_t::CLASS_VEHICLE;
    }
    if (ev->timestamp < run.killed_utime) {
      ++lists_before;
      for (const track_t& t : m.tracks) before_ids.insert(t.id);
      confirmed_before = confirmed;
    } else if (ev->timestamp > run.restarted_utime) {
      ++lists_after;
      if (first_after_utime == 0) first_after_utime = m.utime;
      for (const track_t& t : m.tracks) reused += before_ids.count(t.id) > 0;
      confirmed_after[m.utime] = confirmed;
    }
  }
  std::printf("before the kill: %d track lists, %zu ids, %d confirmed vehicles at the end; after: %d lists\n",
              lists_before, before_ids.size(), confirmed_before, lists_after);
  ASSERT_GT(lists_before, 100);  // 8 s at 25 Hz
  ASSERT_GT(lists_after, 100);
  ASSERT_GT(confirmed_before, 0);
  EXPECT_EQ(reused, 0);
  int back_within_1s = 0;
  for (const auto& [utime, n] : confirmed_after) {
    if (utime <= first_after_utime + 1'000'000) back_within_1s = std::max(back_within_1s, n);
  }
  std::printf("after the restart: %d confirmed vehicles within 1 s of its first TRACKS\n", back_within_1s);
  EXPECT_GE(back_within_1s, confirmed_before);
}

std::int64_t Reason(const tracker_status_t& s, const std::string& reason) {
  for (int i = 0; i < s.num_reasons; ++i) {
    if (s.reject_reason[i] == reason) return s.reject_count[i];
  }
  return 0;
}

// What a live publisher said it sent: "NAME: stopped: N <what> published, ..." (-1 if not said).
std::int64_t PublishedCount(const std::string& log_path) {
  const std::string text = ReadFile(log_path);
  const std::size_t at = text.rfind("stopped: ");
  if (at == std::string::npos) return -1;
  return std::strtoll(text.c_str() + at + 9, nullptr, 10);
}

// The live tracker stopped (SIGSTOP) for 3 s mid-lap: on resuming it finds 3 s of poses and scans
// waiting, and whatever its receive queues could not hold is lost. Every pose and scan the
// publishers sent (their own counts) is either received or counted lost (pose_gap,
// scan_seq_gap), and with the queues sized for the stall nothing is lost.
TEST(TrackerLiveTest, StoppedTrackerLosesNothingUncounted) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const LiveRun run = RunLive("paper_fig4_turn", 16.0, 1.0, {TrackerFault::Kind::kStop, 6.0, 3.0});
  const std::int64_t poses_sent = PublishedCount(run.dir + "/ego.txt");
  const std::int64_t scans_sent = PublishedCount(run.dir + "/driver.txt");
  const tracker_status_t st = LastStatus(run.live_log);
  const std::int64_t pose_gap = Reason(st, "pose_gap"), scan_gap = Reason(st, "scan_seq_gap");
  std::printf("poses sent %lld, received %lld, counted lost %lld; scans sent %lld, received %lld, "
              "counted lost %lld\n",
              static_cast<long long>(poses_sent), static_cast<long long>(st.poses_received),
              static_cast<long long>(pose_gap), static_cast<long long>(scans_sent),
              static_cast<long long>(st.scans_received), static_cast<long long>(scan_gap));
  ASSERT_GT(poses_sent, 1500);  // 16 s at 100 Hz
  ASSERT_GT(scans_sent, 390);   // 16 s at 25 Hz
  EXPECT_EQ(st.poses_received + pose_gap, poses_sent);
  EXPECT_EQ(st.scans_received + scan_gap, scans_sent);
  EXPECT_EQ(pose_gap, 0);
  EXPECT_EQ(scan_gap, 0);
}

TEST(TrackerLiveTest, UrbanIntersectionLiveWith64LayerScans) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  // 12 s of the busy intersection: 2.8 MB scans at 10 Hz over the loopback bus (in slow motion
  // in a sanitizer build, whose instrumented tracker cannot keep up with them: LiveRate()).
  const LiveRun run = RunLive("urban_intersection", 12.0, LiveRate());
  const EvalResult r = EvaluateTracks(run.live_log, run.live_log);
  std::printf("live urban_intersection (12 s): %s\n", Summary(r).c_str());
  const tracker_status_t st = LastStatus(run.live_log);
  std::printf("tracker: %lld scans received, %lld processed, median latency %.1f ms\n",
              static_cast<long long>(st.scans_received), static_cast<long long>(st.scans_processed),
              st.median_latency_ms);
  EXPECT_GE(st.scans_processed, 110);  // of 120: the large socket buffer keeps (nearly) all
  // Live, the pool's two threads are pinned to two CPUs (compute.pin_threads) where the
  // process may use exactly two, and may pin a thread (a container may refuse it).
  std::set<std::string> single_cpus;
  for (const std::string& cpus : run.tracker_thread_cpus) {
    std::printf("tracker thread: CPUs %s\n", cpus.c_str());
    if (cpus.find_first_of(",-") == std::string::npos) single_cpus.insert(cpus);
  }
  cpu_set_t own;
  CPU_ZERO(&own);
  ASSERT_EQ(sched_getaffinity(0, sizeof(own), &own), 0);
  if (CPU_COUNT(&own) == 2 && CanPinAThread(AffinityOf(pthread_self()).front())) {
    EXPECT_EQ(single_cpus.size(), 2u) << "threads pinned to a CPU of their own";
  }
  EXPECT_GT(r.due, 500);
  for (const auto& m : r.misses) std::printf("  %s\n", m.c_str());
  for (const auto& [vehicle, ids] : r.ids) {
    if (ids.size() < 2) continue;
    std::printf("  vehicle %lld: tracks", static_cast<long long>(vehicle));
    for (const auto id : ids) std::printf(" %lld", static_cast<long long>(id));
    std::printf("\n");
  }
  for (const auto& m : r.switches) std::printf("  switch %s\n", m.c_str());
  // Two criteria. The bus: the live run scores what the same lap scores offline (the same
  // tracks, below, when nothing was lost); a scan lost on the bus may cost a few pairs and a
  // switch. The tracker: on the lap, every due vehicle tracked and no identity switch, with
  // the slack the start time calls for. The RANSAC draws follow each scan's utime, and the lap
  // starts at the wall clock: over 100 start times (offline, the same 12 s lap), 99 tracked all
  // 2160 due pairs without a switch; one (start utime 1796326980349029) tracked 2157 with one
  // switch, a parked car 33-39 m away whose young track took a false 1.3 m/s from its first
  // fits and lost it for three scans (tracker/README.md, open problems).
  //   vtrack-sim-log --scenario urban_intersection --start-utime U --duration 12 --out s.lcm
  //   vtrack-tracker --input s.lcm --output t.lcm; tracker-eval-scores s.lcm t.lcm
  const EvalResult off = EvaluateTracks(run.sim_log, run.offline);
  std::printf("offline urban_intersection (12 s): %s\n", Summary(off).c_str());
  EXPECT_GE(off.matched + 3, off.due) << (off.misses.empty() ? "" : off.misses.front());
  EXPECT_LE(off.id_switches, 1) << (off.switches.empty() ? "" : off.switches.front());
  // Pairs are due at the scans that have TRACKS: a scan lost live is a scan fewer to score.
  if (st.scans_processed == LastStatus(run.offline).scans_processed) {
    // At most one pair short of offline: the live recording comes in two variants (poses and
    // scans interleave differently on the bus), and on one of them the tracker misses vehicle 4
    // for one scan at t = 6.4 s, offline as live (tracker/README.md, open problems).
    EXPECT_LE(r.due - r.matched, off.due - off.matched + 1) << (r.misses.empty() ? "" : r.misses.front());
    EXPECT_LE(r.id_switches, off.id_switches) << (r.switches.empty() ? "" : r.switches.front());
  } else {
    EXPECT_GE(r.matched * 1000, r.due * 990) << (r.misses.empty() ? "" : r.misses.front());
    EXPECT_LE(r.id_switches, off.id_switches + 1) << (r.switches.empty() ? "" : r.switches.front());
  }
  EXPECT_EQ(r.max_hyps_not_moving, 1);
  EXPECT_LE(r.max_hyps_moving, 4);
  EXPECT_EQ(r.max_hyps_stationary_truth, 1);  // no parked car is judged a mover
  // Live and offline: the same tracks when nothing is lost on the bus.
  // A scan whose poses came late (a loaded machine) is compensated with an extrapolated pose:
  // then its returns, and the tracks, differ slightly from the offline run.
  std::int64_t extrapolated = 0;
  for (int i = 0; i < st.num_reasons; ++i) {
    std::printf("  live reject %s: %lld\n", st.reject_reason[static_cast<std::size_t>(i)].c_str(),
                static_cast<long long>(st.reject_count[static_cast<std::size_t>(i)]));
    if (st.reject_reason[static_cast<std::size_t>(i)] == "pose_extrapolated") {
      extrapolated = st.reject_count[static_cast<std::size_t>(i)];
    }
  }
  if (st.scans_processed == LastStatus(run.offline).scans_processed && extrapolated == 0) {
    EXPECT_GT(CompareTracks(TracksByUtime(run.live_log), TracksByUtime(run.offline), 1e-9), 100);
  }
  std::filesystem::remove(run.sim_log);
  std::filesystem::remove(run.live_log);
}

// Tracks `input` offline with `tracker_args`, then plays it live with lcm-logplayer (at
// LiveRate()) into a live vtrack-tracker with the same arguments; returns the scans whose TRACKS
// match (same ids, states within 1e-9: nothing is lost on loopback, and the tracker depends on
// message contents and order only).
int PlayLiveAndCompare(const std::string& dir, const std::string& input,
                       const std::vector<std::string>& tracker_args) {
  const std::string offline = dir + "/offline.lcm", live = dir + "/live.lcm";
  std::vector<std::string> off = {Bin("vtrack-tracker"), "--input", input, "--output", offline, "-q"};
  off.insert(off.end(), tracker_args.begin(), tracker_args.end());
  EXPECT_EQ(RunCommand(off, dir + "/offline.txt"), 0) << ReadFile(dir + "/offline.txt");
  {
    Subprocess logger({"lcm-logger", "-q", "-f", "-c", "TRACKS", kLoggerUrl, live}, dir + "/logger.txt");
    std::vector<std::string> on = {Bin("vtrack-tracker"), "--first-track-id", "1"};
    on.insert(on.end(), tracker_args.begin(), tracker_args.end());
    Subprocess tracker(on, dir + "/tracker.txt");
    std::this_thread::sleep_for(1s);
    const int rc = RunCommand({"lcm-logplayer", "-s", std::to_string(LiveRate()), "-l",
                               "udpm://239.255.76.67:7667?ttl=0", input},
                              dir + "/player.txt", 600s);
    EXPECT_EQ(rc, 0) << ReadFile(dir + "/player.txt");
    std::this_thread::sleep_for(2s);
    EXPECT_EQ(tracker.Stop(), 0) << ReadFile(dir + "/tracker.txt");
    std::this_thread::sleep_for(300ms);
    logger.Stop();
  }
  return CompareTracks(TracksByUtime(live), TracksByUtime(offline), 1e-9);
}

TEST(TrackerLiveTest, LogPlayedLiveGivesTheSameTracksAsOffline) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string dir = ScratchDir("tracker_logplayer");
  const std::string sim = dir + "/sim.lcm";
  ASSERT_EQ(RunCommand({Bin("vtrack-sim-log"), "--scenario", "paper_fig4_turn", "--duration", "8",
                        "--out", sim, "-q"}, dir + "/sim.txt"), 0);
  EXPECT_GT(PlayLiveAndCompare(dir, sim, {}), 190);
}

// KITTI 0000's first 60 frames (64-beam scans, PointRCNN boxes, ego poses) played live into the
// tracker in fused mode: the same tracks as the offline run.
TEST(TrackerLiveTest, KittiFusedPlayedLiveGivesTheSameTracksAsOffline) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string kitti = KittiDir();
  if (kitti.empty()) GTEST_SKIP() << "KITTI tracking 0000 not found under " << DataDir();
  const std::string dir = ScratchDir("tracker_kitti_fused_live");
  const std::string log = dir + "/kitti.lcm";
  ASSERT_EQ(RunCommand({Bin("vtrack-kitti2lcm"), "--kitti", kitti, "--sequence", "0000",
                        "--num-frames", "60", "--out", log}, dir + "/convert.txt"), 0)
      << ReadFile(dir + "/convert.txt");
  EXPECT_GE(PlayLiveAndCompare(dir, log, {"--input-mode", "fused"}), 58);
  std::filesystem::remove(log);
}

// The sweeps a driver says it published ("stopped: N scans published, K skipped"), or -1.
long long PublishedScans(const std::string& driver_output) {
  const std::string key = "stopped: ";
  const std::size_t at = driver_output.rfind(key);
  long long published = -1;
  if (at == std::string::npos ||
      std::sscanf(driver_output.c_str() + at + key.size(), "%lld scans published", &published) != 1) {
    return -1;
  }
  return published;
}

// The KITTI fused demo on the bus: vtrack-ladar-driver replays KITTI 0000's sweeps (as slices),
// ground truth and PointRCNN boxes, vtrack-ego-pose its poses, and a live tracker in fused mode
// tracks them while lcm-logger records everything. The recorded inputs tracked offline give the
// same tracks.
TEST(TrackerLiveTest, KittiFusedDemoLiveGivesTheOfflineTracks) {
  VTRACK_REQUIRE_PRIVATE_NETNS();
  const std::string kitti = KittiDir();
  if (kitti.empty()) GTEST_SKIP() << "KITTI tracking 0000 not found under " << DataDir();
  // 154 sweeps of 123k returns at a fifth of real time would add minutes to the sanitizer run;
  // the same path is covered there by KittiFusedPlayedLiveGivesTheSameTracksAsOffline.
  if (kSanitizedBuild) GTEST_SKIP() << "the whole KITTI demo runs in the Release tree only";
  const std::string dir = ScratchDir("tracker_kitti_fused_demo");
  const std::string live = dir + "/live.lcm", offline = dir + "/offline.lcm";
  const std::string u = std::to_string(lcm_util::WallUtime() + 3'000'000);
  const std::string rate = std::to_string(LiveRate());
  {
    Subprocess logger({"lcm-logger", "-q", "-f", kLoggerUrl, live}, dir + "/logger.txt");
    Subprocess tracker({Bin("vtrack-tracker"), "--first-track-id", "1", "--input-mode", "fused"},
                       dir + "/tracker.txt");
    std::this_thread::sleep_for(500ms);
    Subprocess ego({Bin("vtrack-ego-pose"), "--kitti", kitti, "--start-utime", u, "--laps", "1",
                    "--rate", rate, "-q"}, dir + "/ego.txt");
    Subprocess driver({Bin("vtrack-ladar-driver"), "--kitti", kitti, "--start-utime", u, "--laps",
                       "1", "--rate", rate, "-q"}, dir + "/driver.txt");
    const auto rd = driver.Wait(std::chrono::seconds(static_cast<int>(3 + 16 / LiveRate() + 60)));
    EXPECT_TRUE(rd && *rd == 0) << ReadFile(dir + "/driver.txt");
    const auto re = ego.Wait(10s);
    EXPECT_TRUE(re && *re == 0) << ReadFile(dir + "/ego.txt");
    std::this_thread::sleep_for(1s);
    EXPECT_EQ(tracker.Stop(), 0) << ReadFile(dir + "/tracker.txt");
    std::this_thread::sleep_for(300ms);
    logger.Stop();
  }
  // Boxes arrived on DETECTIONS, and the sweeps as slices.
  int detection_lists = 0, slices = 0;
  {
    lcm_util::LogReader reader(live);
    while (const lcm::LogEvent* ev = reader.Next()) {
      detection_lists += ev->channel == "DETECTIONS";
      slices += ev->channel == "LADAR_SLICE";
    }
  }
  // A driver starved of CPU for over 0.5 s skips the overdue sweeps (sensor_driver/README.md),
  // as a loaded 2-core machine may make it: each sweep it published is on the bus and tracked.
  const long long published = PublishedScans(ReadFile(dir + "/driver.txt"));
  EXPECT_GE(published, 154 * 9 / 10) << ReadFile(dir + "/driver.txt");
  EXPECT_LE(published, 154);
  EXPECT_EQ(detection_lists, published);
  EXPECT_GT(slices, published * 10);
  ASSERT_EQ(RunCommand({Bin("vtrack-tracker"), "--input", live, "--output", offline,
                        "--input-mode", "fused", "-q"}, dir + "/offline.txt"), 0)
      << ReadFile(dir + "/offline.txt");
  EXPECT_GE(CompareTracks(TracksByUtime(live), TracksByUtime(offline), 1e-9), published - 4);
  const tracker_status_t st = LastStatus(live);
  EXPECT_EQ(st.scans_processed, published);
  std::filesystem::remove(live);
  std::filesystem::remove(offline);
}

}  // namespace
}  // namespace vtrack::testing
